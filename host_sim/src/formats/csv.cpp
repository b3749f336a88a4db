#include "ascorr_host/formats/csv.hpp"

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <system_error>

#include "ascorr_text/input_error.hpp"
#include "ascorr_text/line_limit.hpp"
#include "ascorr_text/numbers.hpp"

namespace ascorr::host {

BlockReader::BlockReader(std::string path, std::size_t block_bytes)
    : path_(std::move(path)), block_bytes_(block_bytes) {
    text::refuse_directory(path_);
    f_ = std::fopen(path_.c_str(), "rb");
    if (f_ == nullptr) {
        throw text::cannot_open(path_, std::strerror(errno));
    }
}

BlockReader::~BlockReader() {
    if (f_ != nullptr) {
        std::fclose(f_);
    }
}

std::size_t count_line_ends(std::string_view text) noexcept {
    std::size_t n = 0;
    const char* p = text.data();
    const char* const end = p + text.size();
    while (p != end) {
        const void* nl = std::memchr(p, '\n', static_cast<std::size_t>(end - p));
        if (nl == nullptr) {
            break;
        }
        ++n;
        p = static_cast<const char*>(nl) + 1;
    }
    return n;
}

bool BlockReader::next(std::string_view& block) {
    // Keep the partial last line of the previous block (none on the first call,
    // when the buffer is not allocated yet: memmove must not see a null pointer).
    if (size_ > consumed_) {
        std::memmove(buf_.get(), buf_.get() + consumed_, size_ - consumed_);
    }
    size_ -= consumed_;
    consumed_ = 0;
    lines_before_ += lines_in_last_;
    lines_in_last_ = 0;
    const auto has_line_end = [&] { return size_ != 0 && std::memchr(buf_.get(), '\n', size_) != nullptr; };
    // Read until the buffer holds a block's worth with a line end (or the file ends).
    while (!eof_ && (size_ < block_bytes_ || !has_line_end())) {
        if (capacity_ - size_ < block_bytes_) {  // grow: first call, or a line longer than a block
            const std::size_t cap = std::max(2 * capacity_, size_ + block_bytes_);
            std::unique_ptr<char[]> bigger(new char[cap]);
            if (size_ != 0) {
                std::memcpy(bigger.get(), buf_.get(), size_);
            }
            buf_ = std::move(bigger);
            capacity_ = cap;
        }
        const std::size_t n = std::fread(buf_.get() + size_, 1, block_bytes_, f_);
        if (!scan_.feed(std::string_view(buf_.get() + size_, n))) {
            throw text::InputError(path_, scan_.too_long_line(), 0, text::line_too_long());
        }
        size_ += n;
        if (n == 0) {
            if (std::ferror(f_) != 0) {
                throw text::cannot_read(path_, std::strerror(errno));
            }
            eof_ = true;
        }
    }
    if (size_ == 0) {
        return false;
    }
    const std::string_view all(buf_.get(), size_);
    const std::size_t last_nl = all.rfind('\n');
    consumed_ = eof_ || last_nl == std::string_view::npos ? size_ : last_nl + 1;
    block = all.substr(0, consumed_);
    if (std::memchr(block.data(), '\0', block.size()) != nullptr) {
        text::refuse_binary(path_, block, lines_before_ + 1);  // throws, as read_text_file does
    }
    lines_in_last_ = count_line_ends(block) + (block.back() != '\n' ? 1 : 0);
    return true;
}

void split_row(std::string_view line, std::size_t count, const std::string& file, std::size_t n,
               std::vector<std::string_view>& fields, std::vector<std::size_t>& starts) {
    if (const std::size_t bad = split_fields(line, fields, starts); bad != kSplitOk) {
        throw text::InputError(file, n, bad + 1, why_split_failed(line, bad));
    }
    if (fields.size() != count) {
        throw text::InputError(file, n, starts.back() + 1,
                               "expected " + std::to_string(count) + " fields, found " + std::to_string(fields.size()));
    }
}

namespace {
// x with 15 decimals for |x| < 1 (quaternion components), correctly rounded
// like printf: the product x·1e15 is made exact as p + e with an FMA, then
// rounded half to even. 10x faster than the general to_chars.
char* format_unit_15(char* out, double x) noexcept {
    const double ax = std::fabs(x);
    const double p = ax * 1e15;
    const double e = std::fma(ax, 1e15, -p);  // exact: ax·1e15 = p + e
    double r = std::nearbyint(p);             // round half even
    const double d = (p - r) + e;             // exact remainder, |d| ≤ 0.5 + |e|
    if (d > 0.5 || (d == 0.5 && std::fmod(r, 2.0) != 0.0)) {
        r += 1.0;
    } else if (d < -0.5 || (d == -0.5 && std::fmod(r, 2.0) != 0.0)) {
        r -= 1.0;
    }
    const auto digits = static_cast<std::uint64_t>(r);  // ≤ 1e15
    if (std::signbit(x)) {                              // as printf: -0.000… for negative zero and tiny negatives
        *out++ = '-';
    }
    const std::uint64_t int_part = digits / 1000000000000000ULL;
    const std::uint64_t frac = digits % 1000000000000000ULL;
    *out++ = static_cast<char>('0' + int_part);
    *out++ = '.';
    // 15 digits as 7 + 8, two at a time from a table, in 32-bit arithmetic.
    static constexpr char kDigitPairs[] =
        "00010203040506070809101112131415161718192021222324252627282930313233343536373839"
        "40414243444546474849505152535455565758596061626364656667686970717273747576777879"
        "8081828384858687888990919293949596979899";
    auto hi = static_cast<std::uint32_t>(frac / 100000000U);  // 7 digits
    auto lo = static_cast<std::uint32_t>(frac % 100000000U);  // 8 digits
    for (int i = 13; i >= 7; i -= 2) {
        std::memcpy(out + i, kDigitPairs + 2 * (lo % 100U), 2);
        lo /= 100U;
    }
    for (int i = 5; i >= 1; i -= 2) {
        std::memcpy(out + i, kDigitPairs + 2 * (hi % 100U), 2);
        hi /= 100U;
    }
    out[0] = static_cast<char>('0' + hi);
    return out + 15;
}
}  // namespace

char* format_fixed(char* out, char* end, double x, int decimals) noexcept {
    if (decimals == 15 && std::fabs(x) < 1.0 && end - out >= 18) {
        return format_unit_15(out, x);
    }
    const auto r = std::to_chars(out, end, x, std::chars_format::fixed, decimals);
    return r.ec == std::errc() ? r.ptr : out;
}

Header::Header(std::string_view line, const std::string& file) {
    if (line.substr(0, 3) == "\xEF\xBB\xBF") {  // a UTF-8 byte-order mark (spreadsheet exports)
        line.remove_prefix(3);
    }
    if (line.find('\r') != std::string_view::npos) {
        throw text::InputError(
            file, 1, line.find('\r') + 1,
            "carriage return inside the header: the file has CR-only line ends (classic Mac); convert "
            "them to LF or CRLF");
    }
    std::vector<std::string_view> fields;
    std::vector<std::size_t> starts;
    if (const std::size_t bad = split_fields(line, fields, starts); bad != kSplitOk) {
        throw text::InputError(file, 1, bad + 1, why_split_failed(line, bad));
    }
    for (std::size_t i = 0; i < fields.size(); ++i) {
        const std::string name = unquoted(fields[i]);  // "note" names the column note
        raw_names_.emplace_back(fields[i]);
        if (name.empty()) {
            throw text::InputError(file, 1, starts[i] + 1, "empty column name in the header");
        }
        for (const auto& n : names_) {
            if (n == name) {
                throw text::InputError(file, 1, starts[i] + 1, "column '" + name + "' appears twice in the header");
            }
        }
        names_.push_back(name);
    }
}

int Header::index(std::string_view name) const noexcept {
    for (std::size_t i = 0; i < names_.size(); ++i) {
        if (names_[i] == name) {
            return static_cast<int>(i);
        }
    }
    return -1;
}

}  // namespace ascorr::host
