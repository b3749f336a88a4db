#include "ascorr_host/csv.hpp"

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <cstdio>
#include <cstring>
#include <memory>

#include "ascorr_host/input_error.hpp"

namespace ascorr::host {

std::string read_text_file(const std::string& path) {
    std::unique_ptr<std::FILE, int (*)(std::FILE*)> f(std::fopen(path.c_str(), "rb"), &std::fclose);
    if (!f) {
        throw InputError(path, 0, 0, std::string("cannot open: ") + std::strerror(errno));
    }
    std::string data;
    char buf[1 << 16];
    std::size_t n = 0;
    while ((n = std::fread(buf, 1, sizeof buf, f.get())) > 0) {
        data.append(buf, n);
    }
    if (std::ferror(f.get()) != 0) {
        throw InputError(path, 0, 0, "read error");
    }
    if (data.find('\0') != std::string::npos) {
        const std::size_t at = data.find('\0');
        const std::size_t line = 1 + static_cast<std::size_t>(std::count(data.begin(), data.begin() + static_cast<std::ptrdiff_t>(at), '\n'));
        throw InputError(path, line, 0, "binary data (NUL byte) in a text file");
    }
    return data;
}

bool LineReader::next(std::string_view& line) noexcept {
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

void split_fields(std::string_view line, std::vector<std::string_view>& fields, std::vector<std::size_t>& starts) {
    fields.clear();
    starts.clear();
    std::size_t start = 0;
    for (;;) {
        const std::size_t comma = line.find(',', start);
        starts.push_back(start);
        if (comma == std::string_view::npos) {
            fields.push_back(line.substr(start));
            return;
        }
        fields.push_back(line.substr(start, comma - start));
        start = comma + 1;
    }
}

std::optional<double> parse_double(std::string_view field) noexcept {
    if (field.empty()) {
        return std::nullopt;
    }
    const char* first = field.data();
    const char* last = first + field.size();
    if (*first == '+') {  // from_chars rejects a leading '+', CSV writers emit it
        ++first;
    }
    double x = 0.0;
    const auto [ptr, ec] = std::from_chars(first, last, x);
    if (ec == std::errc::result_out_of_range) {
        return std::nullopt;
    }
    if (ec != std::errc() || ptr != last) {
        return std::nullopt;
    }
    return x;
}

std::optional<long long> parse_integer(std::string_view field) noexcept {
    if (field.empty()) {
        return std::nullopt;
    }
    long long x = 0;
    const auto [ptr, ec] = std::from_chars(field.data(), field.data() + field.size(), x);
    if (ec != std::errc() || ptr != field.data() + field.size()) {
        return std::nullopt;
    }
    return x;
}

char* format_fixed(char* out, char* end, double x, int decimals) noexcept {
    const auto r = std::to_chars(out, end, x, std::chars_format::fixed, decimals);
    return r.ec == std::errc() ? r.ptr : out;
}

Header::Header(std::string_view line, const std::string& file) {
    std::vector<std::string_view> fields;
    std::vector<std::size_t> starts;
    split_fields(line, fields, starts);
    for (std::size_t i = 0; i < fields.size(); ++i) {
        const std::string name(fields[i]);
        if (name.empty()) {
            throw InputError(file, 1, starts[i] + 1, "empty column name in the header");
        }
        for (const auto& n : names_) {
            if (n == name) {
                throw InputError(file, 1, starts[i] + 1, "column '" + name + "' appears twice in the header");
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
