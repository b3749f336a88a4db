// ascorr_text/line_reader.hpp: a text's lines, one at a time, for every reader
// of the host and the HAL (one copy of the line splitting).
//
// A line ends at '\n'; a '\r' before it is dropped (CRLF files), a last line
// without '\n' is a line. The text is not copied: the lines are views into it,
// valid while it is. Bounded by the text; no allocation.
#pragma once

#include <cstddef>
#include <string_view>

namespace ascorr::text {

class LineReader {
public:
    // lines_before: how many lines of the file precede text (for numbering).
    explicit LineReader(std::string_view text, std::size_t lines_before = 0) noexcept
        : text_(text), line_(lines_before) {}

    // The next line without its line end; false at the end of the text.
    bool next(std::string_view& line) noexcept {
        if (pos_ >= text_.size()) {
            return false;
        }
        std::size_t end = text_.find('\n', pos_);
        if (end == std::string_view::npos) {
            end = text_.size();
        }
        line = text_.substr(pos_, end - pos_);
        if (!line.empty() && line.back() == '\r') {
            line.remove_suffix(1);
        }
        pos_ = end + 1;
        ++line_;
        return true;
    }

    // The number of the line last returned (lines_before + lines read).
    std::size_t line_number() const noexcept { return line_; }
    // True when the line last returned was the text's last.
    bool at_end() const noexcept { return pos_ >= text_.size(); }

private:
    std::string_view text_;
    std::size_t pos_ = 0;
    std::size_t line_ = 0;
};

}  // namespace ascorr::text
