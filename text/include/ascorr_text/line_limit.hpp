// ascorr_text/line_limit.hpp: the longest line any of ascorr's text
// readers accepts, and the scan that finds a longer one as a file is read.
//
// One limit for every reader (solutions, model, states; the HAL's board
// configuration, replay and history files), so that no input, however
// hostile (/dev/zero, one line of 20 MB), makes a reader hold more than a
// bounded buffer before it refuses it with file:line. The longest real line
// of these formats is a few hundred bytes; a solutions row with copied
// columns of a few kilobytes. Part of ascorr_text, the small library below
// both the HAL's readers and the host's.
//
// Conventions: a line's length excludes its line end ('\n'); lines are
// numbered from 1.
#pragma once

#include <cstddef>
#include <cstring>
#include <string>
#include <string_view>

namespace ascorr::text {

inline constexpr std::size_t kMaxLineBytes = std::size_t{1} << 20;  // 1 MiB

// The refusal text of a line beyond kMaxLineBytes (the caller adds file:line).
inline std::string line_too_long() {
    return "line longer than " + std::to_string(kMaxLineBytes) +
           " bytes (1 MiB): not a text file of this format (a binary or a file without line ends?)";
}

// Fed a file's bytes in order, in pieces of any size: finds the first line
// longer than kMaxLineBytes as soon as its first kMaxLineBytes + 1 bytes are in.
class LineLengthScan {
public:
    // False once a line is too long (too_long_line() is its number).
    bool feed(std::string_view piece) noexcept {
        const char* p = piece.data();
        const char* const end = p + piece.size();
        while (p != end) {
            const auto* nl = static_cast<const char*>(std::memchr(p, '\n', static_cast<std::size_t>(end - p)));
            const std::size_t n = static_cast<std::size_t>((nl == nullptr ? end : nl) - p);
            if (length_ + n > kMaxLineBytes) {
                return false;
            }
            if (nl == nullptr) {
                length_ += n;
                break;
            }
            length_ = 0;
            ++line_;
            p = nl + 1;
        }
        return true;
    }
    std::size_t too_long_line() const noexcept { return line_ + 1; }

private:
    std::size_t length_ = 0;  // of the line being read
    std::size_t line_ = 0;    // complete lines so far
};

}  // namespace ascorr::text
