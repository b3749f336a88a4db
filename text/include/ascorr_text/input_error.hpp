// ascorr_text/input_error.hpp: where and why an input file is wrong: the one
// error type of every text reader (the host's formats, the HAL's board
// configuration, replay and history files).
//
// Every reader reports a malformed input as file:line:column plus a sentence,
// the way compilers do, so that an editor can jump to it. Lines and columns
// count from 1; 0 means none and is left out of the message, which then reads
// "file:line: what" or "file: what", never file:0:0:. The file is named as
// messages show it (input_name.hpp: "standard input" for the copy of standard
// input). whole_file(): a message that names the file itself ("cannot open
// FILE: reason", the HAL's readers' words).
#pragma once

#include <cstddef>
#include <stdexcept>
#include <string>
#include <utility>

#include "ascorr_text/input_name.hpp"

namespace ascorr::text {

class InputError : public std::runtime_error {
public:
    InputError(const std::string& file, std::size_t line, std::size_t column, const std::string& what)
        : std::runtime_error(where(input_name(file), line, column) + what),
          file_(input_name(file)),
          line_(line),
          column_(column) {}

    // An error about the whole file `file`, whose message names it itself.
    static InputError whole_file(const std::string& file, const std::string& message) {
        return InputError(input_name(file), message);
    }

    // The file as messages show it.
    const std::string& file() const noexcept { return file_; }
    std::size_t line() const noexcept { return line_; }
    std::size_t column() const noexcept { return column_; }

private:
    InputError(std::string shown, const std::string& message)
        : std::runtime_error(message), file_(std::move(shown)), line_(0), column_(0) {}

    static std::string where(const std::string& shown, std::size_t line, std::size_t column) {
        if (line == 0U) {
            return shown + ": ";
        }
        return shown + ":" + std::to_string(line) + (column == 0U ? "" : ":" + std::to_string(column)) + ": ";
    }

    std::string file_;
    std::size_t line_;
    std::size_t column_;
};

}  // namespace ascorr::text
