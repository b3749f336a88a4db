// ascorr_host/formats/csv.hpp: the plain CSV dialect of docs/contract.md.
//
// Comma-separated, one header line, LF or CRLF line ends. RFC 4180 quoting
// ("a, ""b""") is accepted in the header and in columns ascorr does not read
// (they are copied verbatim); in a column it reads, a quoted field is refused
// (numbers are written without quotes), and a line break inside quotes is not
// supported (docs/contract.md, section 3). Fields are
// string_views into a buffer that holds the whole file: no copies, no streams;
// numbers are parsed with std::from_chars.
#pragma once

#include <cstddef>
#include <cstdio>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "ascorr_text/csv_fields.hpp"
#include "ascorr_text/line_limit.hpp"
#include "ascorr_text/line_reader.hpp"
#include "ascorr_text/number_fields.hpp"
#include "ascorr_text/text_file.hpp"

namespace ascorr::host {

// The whole content of a file: the one reader of text/ (text_file.hpp), the
// HAL's too.
using text::read_text_file;

// Reads a file in blocks of whole lines, so that a recorded mission of any
// size is processed in bounded memory. Each block ends at a line end (the last
// one may lack it), is free of NUL bytes and has no line beyond
// text::kMaxLineBytes (InputError at file:line otherwise; a NUL byte as
// read_text_file refuses it). A file that cannot be opened: text::cannot_open.
class BlockReader {
public:
    static constexpr std::size_t kDefaultBlockBytes = 32U << 20;
    explicit BlockReader(std::string path, std::size_t block_bytes = kDefaultBlockBytes);
    ~BlockReader();
    BlockReader(const BlockReader&) = delete;
    BlockReader& operator=(const BlockReader&) = delete;

    // The next block of whole lines; false at the end of the file.
    bool next(std::string_view& block);
    // Lines of the file before the block last returned.
    std::size_t lines_before() const noexcept { return lines_before_; }
    const std::string& path() const noexcept { return path_; }

private:
    std::string path_;
    std::size_t block_bytes_;
    std::FILE* f_ = nullptr;
    std::unique_ptr<char[]> buf_;  // not std::string: no zero-fill of each block
    std::size_t capacity_ = 0;
    std::size_t size_ = 0;
    std::size_t consumed_ = 0;  // bytes of buf_ handed out in the last block
    std::size_t lines_before_ = 0;
    std::size_t lines_in_last_ = 0;
    bool eof_ = false;
    text::LineLengthScan scan_;
};

// Number of line ends ('\n') in text; memchr-based, so it runs at memory speed.
std::size_t count_line_ends(std::string_view text) noexcept;

// Iterates the lines of a buffer, keeping 1-based line numbers.
// The line splitting: one copy, in ascorr_text (text/: line_reader.hpp),
// which the HAL's readers use too.
using text::LineReader;

// The field splitter and unquoting of the dialect: one copy, in ascorr_text
// (text/: csv_fields.hpp), which the HAL's readers use too. A quoted
// field (RFC 4180) is one field, handed on as written, quotes included;
// split_fields returns kSplitOk or the 0-based offset where the quoting is
// malformed, why_split_failed() says which; unquoted() gives a field's text.
using text::csv::kSplitOk;
using text::csv::split_fields;
using text::csv::unquoted;
using text::csv::why_split_failed;

// Splits line n of `file` into `fields` (and their 0-based `starts`), which
// must be `count` (the header's): InputError at the malformed quote, or at
// the last field, otherwise. For the model and mountings files.
void split_row(std::string_view line, std::size_t count, const std::string& file, std::size_t n,
               std::vector<std::string_view>& fields, std::vector<std::size_t>& starts);

// A field as a number, and the words for one refused: one syntax for every
// host reader and the Python module (ascorr_text/number_fields.hpp).
using text::number_text;
using text::parse_double;
using text::parse_integer;
using text::why_not_a_number;
using text::why_not_an_integer;

// Formats x with `decimals` digits after the point into out, returns the end.
char* format_fixed(char* out, char* end, double x, int decimals) noexcept;

// The header's columns by name; -1 where absent. Duplicate names are an error.
class Header {
public:
    Header(std::string_view line, const std::string& file);
    int index(std::string_view name) const noexcept;
    std::size_t size() const noexcept { return names_.size(); }
    const std::vector<std::string>& names() const noexcept { return names_; }
    // The names as written (quotes kept), for a header copied into an output.
    const std::vector<std::string>& raw_names() const noexcept { return raw_names_; }
    // The 1-based character column of name i in the header line (the names
    // as written, quotes counted), for messages that point at a column.
    std::size_t column_of(std::size_t i) const noexcept {
        std::size_t column = 1;
        for (std::size_t k = 0; k < i && k < raw_names_.size(); ++k) {
            column += raw_names_[k].size() + 1;
        }
        return column;
    }

private:
    std::vector<std::string> names_;
    std::vector<std::string> raw_names_;
};

}  // namespace ascorr::host
