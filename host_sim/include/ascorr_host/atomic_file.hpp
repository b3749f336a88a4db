// ascorr_host/atomic_file.hpp: all or nothing output files.
//
// Output goes to a temporary file beside the target; commit() flushes it and
// renames it over the target, which POSIX makes atomic. If commit() is never
// reached (an error, an exception), the destructor removes the temporary file,
// so a reader never sees a half-written output.
#pragma once

#include <cstdio>
#include <string>
#include <string_view>

namespace ascorr::host {

class AtomicFile {
public:
    explicit AtomicFile(std::string target);
    ~AtomicFile();
    AtomicFile(const AtomicFile&) = delete;
    AtomicFile& operator=(const AtomicFile&) = delete;

    void write(std::string_view data);
    void commit();

private:
    std::string target_;
    std::string temp_;
    std::FILE* f_ = nullptr;
    bool committed_ = false;
};

// Writes a whole small file atomically.
void write_file_atomically(const std::string& path, std::string_view data);

}  // namespace ascorr::host
