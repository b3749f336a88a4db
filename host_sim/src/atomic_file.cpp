#include "ascorr_host/atomic_file.hpp"

#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <stdexcept>

namespace ascorr::host {

namespace {
[[noreturn]] void io_error(const std::string& what, const std::string& path) {
    throw std::runtime_error(path + ": " + what + ": " + std::strerror(errno));
}
}  // namespace

AtomicFile::AtomicFile(std::string target) : target_(std::move(target)) {
    temp_ = target_ + ".tmp-" + std::to_string(::getpid());
    f_ = std::fopen(temp_.c_str(), "wb");
    if (f_ == nullptr) {
        io_error("cannot create", temp_);
    }
}

AtomicFile::~AtomicFile() {
    if (f_ != nullptr) {
        std::fclose(f_);
    }
    if (!committed_) {
        std::remove(temp_.c_str());
    }
}

void AtomicFile::write(std::string_view data) {
    if (std::fwrite(data.data(), 1, data.size(), f_) != data.size()) {
        io_error("write failed", temp_);
    }
}

void AtomicFile::commit() {
    if (std::fflush(f_) != 0 || ::fsync(::fileno(f_)) != 0) {
        io_error("flush failed", temp_);
    }
    const int rc = std::fclose(f_);
    f_ = nullptr;
    if (rc != 0) {
        io_error("close failed", temp_);
    }
    if (std::rename(temp_.c_str(), target_.c_str()) != 0) {
        io_error("cannot rename into place", target_);
    }
    committed_ = true;
}

void write_file_atomically(const std::string& path, std::string_view data) {
    AtomicFile f(path);
    f.write(data);
    f.commit();
}

}  // namespace ascorr::host
