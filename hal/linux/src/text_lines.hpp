// hal/linux/src/text_lines.hpp: the line and field reader shared by the HAL's
// text files (board configuration, temperature replay, simulation history).
//
// Conventions: lines end at '\n'; a '\r' before it is dropped; line numbers
// start at 1 and columns at 1, as the file:line:column messages give them. A
// final '\n' does not start another line. Private to hal/linux (hal/ cannot
// use host_sim's reader: nothing in hal/ depends on host_sim/).
#pragma once

#include <cerrno>
#include <cstddef>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <string_view>
#include <system_error>
#include <utility>
#include <vector>

#include "ascorr_hal_linux/config_file.hpp"

namespace ascorr::hal::linux_detail {

class TextLines {
public:
    // A UTF-8 byte-order mark at the start is skipped (spreadsheet exports).
    explicit TextLines(std::string_view text) : text_(text) {
        if (text_.substr(0, 3) == "\xEF\xBB\xBF") {
            text_.remove_prefix(3);
        }
    }

    // The next line, without its end; false at the end of the text.
    bool next(std::string_view& line) {
        if (pos_ >= text_.size()) {
            return false;
        }
        std::size_t end = text_.find('\n', pos_);
        if (end == std::string_view::npos) {
            end = text_.size();
        }
        line = text_.substr(pos_, end - pos_);
        pos_ = end + 1;
        ++number_;
        if (!line.empty() && line.back() == '\r') {
            line.remove_suffix(1);
        }
        return true;
    }

    // True when the line last returned was the text's last.
    bool at_end() const { return pos_ >= text_.size(); }

    // The number of the line last returned by next().
    std::size_t number() const { return number_; }

    // The line on which the text ends: where a message about something
    // missing from the whole file points (after a final '\n', the line after).
    std::size_t end_line() const {
        std::size_t n = 1;
        for (const char c : text_) {
            n += c == '\n' ? 1U : 0U;
        }
        return n;
    }

private:
    std::string_view text_;
    std::size_t pos_ = 0;
    std::size_t number_ = 0;
};

// The whole text of a file. A file that cannot be opened or read, or a
// directory: ConfigError "cannot open FILE: reason" (no line, no column).
inline std::string read_text_file(const std::string& path) {
    std::error_code ec;
    if (std::filesystem::is_directory(path, ec)) {
        throw ConfigError::whole_file("cannot open " + path + ": is a directory, not a file");
    }
    std::ifstream in(path, std::ios::binary);
    if (!in) {
        throw ConfigError::whole_file("cannot open " + path + ": " + std::strerror(errno));
    }
    std::ostringstream ss;
    ss << in.rdbuf();
    if (in.bad()) {
        throw ConfigError::whole_file("cannot read " + path + ": " + std::strerror(errno));
    }
    return ss.str();
}

// A field of a comma-separated line and its column (1-based).
using Field = std::pair<std::string_view, std::size_t>;

// The comma-separated fields of a line into `out` (cleared first).
inline void split_fields(std::string_view line, std::vector<Field>& out) {
    out.clear();
    std::size_t start = 0;
    while (true) {
        const std::size_t c = line.find(',', start);
        if (c == std::string_view::npos) {
            out.emplace_back(line.substr(start), start + 1);
            return;
        }
        out.emplace_back(line.substr(start, c - start), start + 1);
        start = c + 1;
    }
}

}  // namespace ascorr::hal::linux_detail
