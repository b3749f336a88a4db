// ascorr_text/csv_fields.hpp: the one field splitter of ascorr's CSV
// dialect (docs/contract.md, section 3), shared by the HAL's text readers
// (text_file.hpp) and the host's (host_sim/src/formats/csv.cpp). It
// is its own small library, ascorr_text (text/CMakeLists.txt), below both:
// host_sim/ may use hal/, hal/ may not use host_sim/, and neither the
// freestanding HAL nor the firmware needs it.
//
// Conventions: a line is given without its line end; offsets are 0-based
// (messages add 1 for the column). RFC 4180 quoting, taken only when the line
// has a quote: a field that begins with '"' runs to the quote that closes it
// ("" inside stands for one quote, commas inside are text) and must end there.
// The field is handed on as written, quotes included, so that a writer copies
// it verbatim; unquoted() gives its text. A line break inside quotes is not
// supported (the line is an unterminated quoted field), nor is text after a
// closing quote: both return the offset where the quoting is malformed.
// Whether a quoted field is acceptable is the reader's decision: in a column it
// reads it is refused, naming the column (quoted_field_refusal()).
#pragma once

#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

namespace ascorr::text::csv {

// split_fields' result when the line split cleanly.
inline constexpr std::size_t kSplitOk = static_cast<std::size_t>(-1);

namespace detail {
// The end of the quoted field opening at line[start] (one past its closing
// quote; a doubled quote is text), or npos when unterminated.
inline std::size_t quoted_field_end(std::string_view line, std::size_t start) {
    std::size_t i = start + 1;
    for (;;) {
        const std::size_t q = line.find('"', i);
        if (q == std::string_view::npos) {
            return q;  // unterminated (a line break inside quotes is not supported)
        }
        if (q + 1 < line.size() && line[q + 1] == '"') {
            i = q + 2;  // a doubled quote
            continue;
        }
        return q + 1;
    }
}

// The quote-aware split (the line has a quote). Appends to fields (and to
// starts, if given); returns kSplitOk or the offset of malformed quoting.
inline std::size_t split_quoted(std::string_view line, std::vector<std::string_view>& fields,
                                std::vector<std::size_t>* starts) {
    std::size_t start = 0;
    for (;;) {
        if (starts != nullptr) {
            starts->push_back(start);
        }
        std::size_t end = start;
        if (start < line.size() && line[start] == '"') {
            end = quoted_field_end(line, start);
            if (end == std::string_view::npos) {
                return start;  // unterminated
            }
            if (end < line.size() && line[end] != ',') {
                return end;  // text after the closing quote
            }
        } else {
            end = line.find(',', start);
            if (end == std::string_view::npos) {
                end = line.size();
            }
        }
        fields.push_back(line.substr(start, end - start));
        if (end >= line.size()) {
            return kSplitOk;
        }
        start = end + 1;
    }
}

// The plain split (no quote in the line): every comma separates.
inline void split_plain(std::string_view line, std::vector<std::string_view>& fields,
                        std::vector<std::size_t>* starts) {
    std::size_t start = 0;
    for (;;) {
        const std::size_t comma = line.find(',', start);
        if (starts != nullptr) {
            starts->push_back(start);
        }
        if (comma == std::string_view::npos) {
            fields.push_back(line.substr(start));
            return;
        }
        fields.push_back(line.substr(start, comma - start));
        start = comma + 1;
    }
}
}  // namespace detail

// Splits a line into fields (reusing the vectors' storage, cleared first) and
// records where each field starts (0-based offset) for messages. Returns
// kSplitOk, or the offset where the quoting is malformed (the fields before it
// are split): why_split_failed() says which.
inline std::size_t split_fields(std::string_view line, std::vector<std::string_view>& fields,
                                std::vector<std::size_t>& starts) {
    fields.clear();
    starts.clear();
    if (line.find('"') != std::string_view::npos) {
        return detail::split_quoted(line, fields, &starts);
    }
    detail::split_plain(line, fields, &starts);
    return kSplitOk;
}

// The same without the offsets (a field's offset is field.data() − line.data()).
inline std::size_t split_fields(std::string_view line, std::vector<std::string_view>& fields) {
    fields.clear();
    if (line.find('"') != std::string_view::npos) {
        return detail::split_quoted(line, fields, nullptr);
    }
    detail::split_plain(line, fields, nullptr);
    return kSplitOk;
}

// Why split_fields stopped at offset `at` of the line.
inline std::string why_split_failed(std::string_view line, std::size_t at) {
    if (at < line.size() && line[at] == '"') {
        return "quoted field without its closing quote (a line break inside quotes is not supported: "
               "docs/contract.md, section 3)";
    }
    return "text after the closing quote of a quoted field";
}

// A field's text without its RFC 4180 quotes ("a ""b""" is a "b"); other
// fields as they are.
inline std::string unquoted(std::string_view field) {
    if (field.size() < 2 || field.front() != '"') {
        return std::string(field);
    }
    std::string out;
    for (std::size_t i = 1; i + 1 < field.size(); ++i) {
        out += field[i];
        if (field[i] == '"') {
            ++i;  // "" is one quote
        }
    }
    return out;
}

// True when a field is quoted (it begins with '"').
inline bool is_quoted(std::string_view field) noexcept {
    return !field.empty() && field.front() == '"';
}

// The refusal of a quoted field in a column a reader reads, after the
// reader's "column 'NAME': ": the field as written, then why.
inline std::string quoted_field_refusal(std::string_view field) {
    return std::string(field) +
           " is a quoted field in a column ascorr reads: write numbers without quotes (docs/contract.md, section 3)";
}

}  // namespace ascorr::text::csv
