// ascorr_text/text_file.hpp: a text file's lines and fields, checked: the
// reader of the HAL's text files (board configuration, temperature replay,
// simulation history), on the one line reader (line_reader.hpp) and field
// splitter (csv_fields.hpp) that the host's readers use too, every refusal an
// InputError (input_error.hpp).
//
// Conventions: lines end at '\n'; a '\r' before it is dropped; line numbers
// start at 1 and columns at 1, as the file:line:column messages give them. A
// final '\n' does not start another line. Every reader of ours, the HAL's and
// the host's, opens a file with read_text_file or refuse_directory and
// cannot_open below, so a file that cannot be opened reads "cannot open FILE:
// reason" everywhere, and a NUL byte is refused by refuse_binary at its line
// and column as soon as it is read. The HAL's readers check the whole file
// as UTF-8 text (TextLines); the host's solutions, model and states readers
// (ascorr_host/formats/csv.hpp, in bounded blocks) refuse a NUL byte only.
#pragma once

#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstddef>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <string_view>
#include <system_error>
#include <utility>
#include <vector>

#include "ascorr_text/c_format.hpp"
#include "ascorr_text/csv_fields.hpp"
#include "ascorr_text/input_error.hpp"
#include "ascorr_text/input_name.hpp"
#include "ascorr_text/line_limit.hpp"
#include "ascorr_text/line_reader.hpp"
#include "ascorr_text/numbers.hpp"

namespace ascorr::text {

// Why a field is not a usable number when it is a well-formed decimal beyond
// double's range ("1e999", "1e-999"): "'1e999' is out of range: ..." in the
// words of ascorr_text/numbers.hpp, as the host's readers say it. Empty for any
// other field, so the caller keeps its own message for malformed text.
inline std::string out_of_range_reason(std::string_view v) {
    double x = 0.0;
    const std::string words = text::out_of_range_words(text::classify_real(v, x, text::LeadingPlus::kRefused));
    return words.empty() ? words : "'" + std::string(v) + "' is out of range: " + words;
}

// `what` unless v is a number beyond double's range: then `prefix` and
// out_of_range_reason(v).
inline std::string number_refusal(std::string_view v, const std::string& what, const std::string& prefix = "") {
    const std::string why = out_of_range_reason(v);
    return why.empty() ? what : prefix + why;
}

// Whether c1 may follow the lead byte c (0xE0 … 0xF4) of a three- or
// four-byte sequence: a continuation byte, narrowed after E0 (no overlong),
// ED (no surrogate), F0 (no overlong) and F4 (nothing beyond U+10FFFF).
constexpr bool utf8_second_ok(unsigned c, unsigned c1) noexcept {
    switch (c) {
        case 0xE0U:
            return c1 >= 0xA0U && c1 <= 0xBFU;
        case 0xEDU:
            return c1 >= 0x80U && c1 <= 0x9FU;
        case 0xF0U:
            return c1 >= 0x90U && c1 <= 0xBFU;
        case 0xF4U:
            return c1 >= 0x80U && c1 <= 0x8FU;
        default:
            return (c1 & 0xC0U) == 0x80U;
    }
}

// The length of the valid UTF-8 sequence at s[i] (1 … 4), or 0 when it is
// not one (a stray continuation byte, a truncated or overlong sequence, a
// surrogate, beyond U+10FFFF). RFC 3629, section 4.
inline std::size_t utf8_length(std::string_view s, std::size_t i) noexcept {
    const auto at = [&](std::size_t k) { return static_cast<unsigned char>(k < s.size() ? s[k] : '\0'); };
    const unsigned c = at(i);
    const auto tail = [&](std::size_t k) { return (at(k) & 0xC0U) == 0x80U; };
    if (c < 0x80U) {
        return 1;
    }
    if (c >= 0xC2U && c <= 0xDFU) {
        return tail(i + 1) ? 2 : 0;
    }
    if (c >= 0xE0U && c <= 0xEFU) {
        return utf8_second_ok(c, at(i + 1)) && tail(i + 2) ? 3 : 0;
    }
    if (c >= 0xF0U && c <= 0xF4U) {
        return utf8_second_ok(c, at(i + 1)) && tail(i + 2) && tail(i + 3) ? 4 : 0;
    }
    return 0;
}

// Up to 24 bytes of a line as printable ASCII: bytes outside 0x20–0x7E, '\\'
// and '"' as \xHH, so that no byte of a binary file reaches the terminal.
inline std::string escaped_excerpt(std::string_view line) {
    static constexpr char kHex[] = "0123456789abcdef";
    std::string out;
    const std::size_t n = line.size() < 24U ? line.size() : 24U;
    for (std::size_t i = 0; i < n; ++i) {
        const auto c = static_cast<unsigned char>(line[i]);
        if (c >= 0x20U && c < 0x7FU && c != '\\' && c != '"') {
            out += static_cast<char>(c);
        } else {
            out += "\\x";
            out += kHex[c >> 4U];
            out += kHex[c & 15U];
        }
    }
    return out + (line.size() > n ? "..." : "");
}

// True when a byte is a control character a text line may not hold: below
// 0x20 but tab (CR before LF is the caller's exception), or DEL.
inline bool is_control(unsigned char c) noexcept {
    return (c < 0x20U && c != '\t') || c == 0x7FU;
}

// True when no byte of the line is a control character (a final CR of a CRLF
// line end excepted): the line is text, whatever its encoding.
inline bool printable_line(std::string_view line) noexcept {
    for (std::size_t i = 0; i < line.size(); ++i) {
        const auto c = static_cast<unsigned char>(line[i]);
        if (is_control(c) && !(c == '\r' && i + 1 == line.size())) {
            return false;
        }
    }
    return true;
}

// Refuses a text that is not UTF-8 text: a NUL or another control character
// (but tab, and CR before LF), DEL, or invalid UTF-8. InputError at the
// first such byte, with an escaped excerpt of its line, never the bytes:
// invalid UTF-8 in an otherwise printable line (a Latin-1 '°', 0xb0) is
// "file:line:column: not UTF-8 text (byte 0xb0; the file may be Latin-1:
// convert it with iconv -f latin1 -t utf-8), line starts \"…\""; anything
// else "file:line:column: binary data (byte 0xHH): not a text file, line
// starts \"…\"" (or a CR not followed by LF).
// first_line: the number of the text's first line (a block of a larger file).
inline void refuse_binary(const std::string& file, std::string_view text, std::size_t first_line = 1) {
    std::size_t line = first_line;
    std::size_t line_start = 0;
    for (std::size_t i = 0; i < text.size();) {
        const auto c = static_cast<unsigned char>(text[i]);
        if (c == '\n') {
            ++line;
            line_start = ++i;
            continue;
        }
        const bool cr_before_lf = c == '\r' && i + 1 < text.size() && text[i + 1] == '\n';
        const bool control = is_control(c) && !cr_before_lf;
        const std::size_t n = control ? 0 : utf8_length(text, i);
        if (n == 0) {
            const std::size_t end = text.find('\n', line_start);
            const std::string_view whole =
                text.substr(line_start, end == std::string_view::npos ? end : end - line_start);
            char byte[8];
            text::c_snprintf(byte, sizeof byte, "0x%02x", c);
            const std::string starts = "line starts \"" + escaped_excerpt(whole) + "\"";
            std::string what;
            if (c >= 0x80U && printable_line(whole)) {
                what = std::string("not UTF-8 text (byte ") + byte +
                       "; the file may be Latin-1: convert it with iconv -f latin1 -t utf-8), " + starts;
            } else if (c == '\r') {
                what = "a CR not followed by LF (CR-only line ends?): not a text file, " + starts;
            } else {
                what = std::string("binary data (byte ") + byte + "): not a text file, " + starts;
            }
            throw text::InputError(file, line, i - line_start + 1, what);
        }
        i += n;
    }
}

class TextLines {
public:
    // Refuses binary data (refuse_binary); a UTF-8 byte-order mark at the
    // start is skipped (spreadsheet exports).
    TextLines(const std::string& file, std::string_view text) : text_(text) {
        refuse_binary(file, text_);
        if (text_.substr(0, 3) == "\xEF\xBB\xBF") {
            text_.remove_prefix(3);
        }
        lines_ = text::LineReader(text_);
    }

    // The next line, without its end; false at the end of the text.
    bool next(std::string_view& line) { return lines_.next(line); }

    // True when the line last returned was the text's last.
    bool at_end() const { return lines_.at_end(); }

    // The number of the line last returned by next().
    std::size_t number() const { return lines_.line_number(); }

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
    text::LineReader lines_{std::string_view{}};
};

// A file that cannot be opened, for `reason`: InputError "cannot open FILE:
// reason", naming the file alone (no line, no column).
inline InputError cannot_open(const std::string& path, const std::string& reason) {
    return InputError::whole_file(path, "cannot open " + input_name(path) + ": " + reason);
}

// A file whose reading failed: "cannot read FILE: reason" (no line, no column).
inline InputError cannot_read(const std::string& path, const std::string& reason) {
    return InputError::whole_file(path, "cannot read " + input_name(path) + ": " + reason);
}

// A directory given as a file: cannot_open(path, "is a directory, not a file").
inline void refuse_directory(const std::string& path) {
    std::error_code ec;
    if (std::filesystem::is_directory(path, ec)) {
        throw cannot_open(path, "is a directory, not a file");
    }
}

// The whole text of a file. A file that cannot be opened, or a directory:
// cannot_open; one that cannot be read: cannot_read. A line
// beyond text::kMaxLineBytes, or a NUL byte (refuse_binary: its line and
// column): InputError as soon as it is read (/dev/zero fails at once, not
// when memory runs out).
inline std::string read_text_file(const std::string& path) {
    refuse_directory(path);
    std::ifstream in(path, std::ios::binary);
    if (!in) {
        throw cannot_open(path, std::strerror(errno));
    }
    std::string text;
    text::LineLengthScan scan;
    char buf[1 << 16];
    while (in.read(buf, sizeof buf) || in.gcount() > 0) {
        const std::string_view piece(buf, static_cast<std::size_t>(in.gcount()));
        if (!scan.feed(piece)) {
            throw text::InputError(path, scan.too_long_line(), 0, text::line_too_long());
        }
        text.append(piece);
        if (piece.find('\0') != std::string_view::npos) {
            refuse_binary(path, text);  // throws: the first byte that is not text, at or before the NUL
        }
    }
    if (in.bad()) {
        throw cannot_read(path, std::strerror(errno));
    }
    return text;
}

// A field of a comma-separated line, as written (quotes included), and its
// column (1-based).
using Field = std::pair<std::string_view, std::size_t>;

// The fields of the lines of a file, split by the dialect's one splitter
// (ascorr_text/csv_fields.hpp: RFC 4180 quoting as docs/contract.md,
// section 3 says). Reuses its storage from line to line.
class FieldSplitter {
public:
    // The fields of line `line_no` of `file`. Malformed quoting (an
    // unterminated quoted field, text after a closing quote): InputError at
    // file:line:column, in the host readers' words.
    const std::vector<Field>& split(const std::string& file, std::size_t line_no, std::string_view line) {
        const std::size_t bad = text::csv::split_fields(line, text_);
        if (bad != text::csv::kSplitOk) {
            throw text::InputError(file, line_no, bad + 1, text::csv::why_split_failed(line, bad));
        }
        fields_.clear();
        for (const std::string_view f : text_) {
            fields_.emplace_back(f, static_cast<std::size_t>(f.data() - line.data()) + 1U);
        }
        return fields_;
    }

private:
    std::vector<std::string_view> text_;
    std::vector<Field> fields_;
};

// A field of a column the reader reads: refused when quoted, naming the
// column ("column 't_chu': \"5\" is a quoted field in a column ascorr reads").
inline void refuse_quoted(const std::string& file, std::size_t line_no, const Field& field, std::string_view column) {
    if (text::csv::is_quoted(field.first)) {
        throw text::InputError(file, line_no, field.second,
                               "column '" + std::string(column) + "': " + text::csv::quoted_field_refusal(field.first));
    }
}

}  // namespace ascorr::text
