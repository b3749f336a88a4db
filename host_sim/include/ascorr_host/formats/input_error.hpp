// ascorr_host/formats/input_error.hpp: where and why an input file is wrong.
//
// Every reader reports a malformed input as file:line:column plus a sentence,
// the way compilers do, so that an editor can jump to it.
#pragma once

#include <cstddef>
#include <stdexcept>
#include <string>

#include "ascorr_text/input_name.hpp"

namespace ascorr::host {

// line or column 0 means "not about a line" (or column): it is left out of
// the message, which then reads file: or file:line:, never file:0:0:. The
// file is named as messages show it (text::input_name: "standard input" for
// the copy of standard input).
class InputError : public std::runtime_error {
public:
    InputError(const std::string& file, std::size_t line, std::size_t column, const std::string& what)
        : std::runtime_error(text::input_name(file) + (line == 0 ? std::string() : ":" + std::to_string(line)) +
                             (line == 0 || column == 0 ? std::string() : ":" + std::to_string(column)) + ": " + what),
          file_(text::input_name(file)),
          line_(line),
          column_(column) {}

    const std::string& file() const noexcept { return file_; }
    std::size_t line() const noexcept { return line_; }
    std::size_t column() const noexcept { return column_; }

private:
    std::string file_;
    std::size_t line_;
    std::size_t column_;
};

}  // namespace ascorr::host
