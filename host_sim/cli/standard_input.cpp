// host_sim/cli/standard_input.cpp: the files of one run, before its work.
//
// Outputs first: every output is checked against the inputs and the other
// outputs and opened (host::OutputSet, atomic_file.hpp), so that a path that
// cannot be written fails before any input is read.
//
// Then the inputs that are streams: "-" (standard input) and every input path
// that names a pipe (/dev/stdin, /dev/fd/N, a shell's <(cmd)), a named FIFO
// or a socket. The readers open their inputs by path and some read one
// twice (stats and plot look at the header, then at the rows; self-calibration
// and --states pass over the rows twice), which a stream cannot give: the
// second pass of a pipe is empty, the second open of a FIFO waits forever. So
// each stream is read once, whole, into a private temporary folder, and the
// input is that copy. The folder is in the signal-cleanup table while it
// exists and is removed when the process returns from main. Every message
// names a copy as the user gave it ("standard input" for "-",
// text::input_name), never by its path. One stream given twice (/dev/stdin and
// "-") is read once.
#include <stdlib.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <memory>
#include <stdexcept>
#include <string>
#include <system_error>
#include <vector>

#include "ascorr_host/formats/atomic_file.hpp"
#include "ascorr_text/input_name.hpp"
#include "commands.hpp"

namespace ascorr::cli {
namespace {

// "-", or a pipe, FIFO or socket by path: what a reader cannot open twice.
// A character device is left to the readers: /dev/null reads empty each
// time, and /dev/zero must meet their line bound, not fill the disk.
bool is_stream(const std::string& path) {
    if (path == "-") {
        return true;
    }
    struct stat st {};
    if (path.empty() || ::stat(path.c_str(), &st) != 0) {
        return false;  // the reader says why it cannot open it
    }
    return S_ISFIFO(st.st_mode) || S_ISSOCK(st.st_mode);
}

class StreamCopies {
public:
    StreamCopies() = default;
    ~StreamCopies() {
        if (folder_.empty()) {
            return;
        }
        std::error_code ec;
        std::filesystem::remove_all(folder_, ec);
        for (const Copy& c : copies_) {
            host::cleanup_release(c.slot);
        }
        host::cleanup_release(folder_slot_);
    }
    StreamCopies(const StreamCopies&) = delete;
    StreamCopies& operator=(const StreamCopies&) = delete;

    // The path of the copy of the stream `given` ("-": standard input).
    std::string copy(const std::string& given) {
        const bool dash = given == "-";
        const std::string shown = dash ? std::string("standard input") : given;
        using File = std::unique_ptr<std::FILE, int (*)(std::FILE*)>;
        File in(dash ? stdin : std::fopen(given.c_str(), "rb"), dash ? [](std::FILE*) { return 0; } : &std::fclose);
        if (!in) {
            return given;  // the reader says why it cannot open it, in its own words
        }
        struct stat st {};
        const bool known = ::fstat(::fileno(in.get()), &st) == 0;
        for (const Copy& c : copies_) {
            if (known && c.dev == st.st_dev && c.ino == st.st_ino) {
                return c.path;  // the same stream by another name: it is read once
            }
        }
        make_folder();
        const std::string path =
            folder_ + (dash ? std::string("/standard-input") : "/input-" + std::to_string(copies_.size() + 1));
        copies_.push_back({known ? st.st_dev : 0, known ? st.st_ino : 0, path, host::cleanup_register_file(path)});
        File out(std::fopen(path.c_str(), "wb"), &std::fclose);
        if (!out) {
            throw std::runtime_error("cannot copy " + shown + " to " + path + ": " + std::strerror(errno));
        }
        char buf[1 << 16];
        std::size_t n = 0;
        while ((n = std::fread(buf, 1, sizeof buf, in.get())) > 0) {
            if (std::fwrite(buf, 1, n, out.get()) != n) {
                throw std::runtime_error("cannot copy " + shown + " to " + path + ": " + std::strerror(errno));
            }
        }
        if (std::ferror(in.get()) != 0) {
            throw std::runtime_error("cannot read " + shown + ": " + std::string(std::strerror(errno)));
        }
        if (std::fflush(out.get()) != 0) {
            throw std::runtime_error("cannot copy " + shown + " to " + path + ": " + std::strerror(errno));
        }
        text::show_input_as(path, shown);
        return path;
    }

private:
    void make_folder() {
        if (!folder_.empty()) {
            return;
        }
        std::string tmpl = (std::filesystem::temp_directory_path() / "ascorr-stdin-XXXXXX").string();
        if (::mkdtemp(tmpl.data()) == nullptr) {
            throw std::runtime_error(std::string("cannot create a temporary folder for the input streams: ") +
                                     std::strerror(errno));
        }
        folder_ = tmpl;
        folder_slot_ = host::cleanup_register_folder(folder_);
    }

    struct Copy {
        dev_t dev;
        ino_t ino;
        std::string path;
        int slot;
    };
    std::string folder_;
    int folder_slot_ = -1;
    std::vector<Copy> copies_;
};

// Two inputs "-" are a usage error, found before anything is opened.
void refuse_two_dashes(const std::vector<std::pair<const char*, std::string*>>& inputs) {
    const char* first = nullptr;
    for (const auto& [option, path] : inputs) {
        if (*path != "-") {
            continue;
        }
        if (first != nullptr) {
            throw CLI::ValidationError(std::string(option) + " -: standard input is already " + first +
                                       "; it can be one input only");
        }
        first = option;
    }
}

}  // namespace

void read_dash_from_standard_input(const std::vector<std::pair<const char*, std::string*>>& inputs) {
    refuse_two_dashes(inputs);
    static StreamCopies copies;  // removed when main returns
    for (const auto& [option, path] : inputs) {
        if (is_stream(*path)) {
            *path = copies.copy(*path);
        }
    }
}

host::OutputSet open_run_files(const std::vector<std::pair<const char*, std::string*>>& inputs,
                               std::vector<host::NamedPath> outputs) {
    refuse_two_dashes(inputs);
    std::vector<host::NamedPath> named;
    for (const auto& [option, path] : inputs) {
        if (!path->empty()) {
            named.push_back({option, *path});
        }
    }
    host::OutputSet set(std::move(outputs), named);
    read_dash_from_standard_input(inputs);
    return set;
}

}  // namespace ascorr::cli
