// host_sim/cli/standard_input.cpp: "-" as an input is standard input.
//
// The readers open their inputs by path and some read one twice (stats and
// plot look at the header, then at the rows; plot reads the temperatures
// again), which a pipe cannot give. So standard input is first copied into
// a private temporary folder, as a file named "standard-input", and the input
// is that file. The folder is in the signal-cleanup table (atomic_file.hpp)
// while it exists and is removed when the process returns from main. Every
// message names that file "standard input" (text::input_name), never its path.
#include <stdlib.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <memory>
#include <stdexcept>
#include <string>
#include <system_error>

#include "ascorr_host/formats/atomic_file.hpp"
#include "ascorr_text/input_name.hpp"
#include "commands.hpp"

namespace ascorr::cli {
namespace {

class StandardInputCopy {
public:
    StandardInputCopy() {
        std::string tmpl = (std::filesystem::temp_directory_path() / "ascorr-stdin-XXXXXX").string();
        if (::mkdtemp(tmpl.data()) == nullptr) {
            throw std::runtime_error(std::string("cannot create a temporary folder for standard input: ") +
                                     std::strerror(errno));
        }
        folder_ = tmpl;
        folder_slot_ = host::cleanup_register_folder(folder_);
        path_ = folder_ + "/standard-input";
        file_slot_ = host::cleanup_register_file(path_);
        std::unique_ptr<std::FILE, int (*)(std::FILE*)> out(std::fopen(path_.c_str(), "wb"), &std::fclose);
        if (!out) {
            throw std::runtime_error("cannot copy standard input to " + path_ + ": " + std::strerror(errno));
        }
        char buf[1 << 16];
        std::size_t n = 0;
        while ((n = std::fread(buf, 1, sizeof buf, stdin)) > 0) {
            if (std::fwrite(buf, 1, n, out.get()) != n) {
                throw std::runtime_error("cannot copy standard input to " + path_ + ": " + std::strerror(errno));
            }
        }
        if (std::ferror(stdin) != 0 || std::fflush(out.get()) != 0) {
            throw std::runtime_error("cannot read standard input: " + std::string(std::strerror(errno)));
        }
        text::show_input_as(path_, "standard input");
    }
    ~StandardInputCopy() {
        std::error_code ec;
        std::filesystem::remove_all(folder_, ec);
        host::cleanup_release(file_slot_);
        host::cleanup_release(folder_slot_);
    }
    StandardInputCopy(const StandardInputCopy&) = delete;
    StandardInputCopy& operator=(const StandardInputCopy&) = delete;
    const std::string& path() const noexcept { return path_; }

private:
    std::string folder_;
    std::string path_;
    int folder_slot_ = -1;
    int file_slot_ = -1;
};

}  // namespace

void read_dash_from_standard_input(const std::vector<std::pair<const char*, std::string*>>& inputs) {
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
    if (first == nullptr) {
        return;
    }
    static const StandardInputCopy copy;  // removed when main returns
    for (const auto& [option, path] : inputs) {
        if (*path == "-") {
            *path = copy.path();
        }
    }
}

}  // namespace ascorr::cli
