#include "ascorr_host/analysis/epochs.hpp"

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <stdexcept>
#include <system_error>

#include "ascorr_host/formats/csv.hpp"
#include "ascorr_host/formats/progress.hpp"

namespace ascorr::host {

void refuse_bad_time_range(const std::optional<double>& from, const std::optional<double>& to, const char* from_name,
                           const char* to_name) {
    const auto text = [](double x) {
        char buf[48];
        std::snprintf(buf, sizeof buf, "%.17g", x);
        return std::string(buf);
    };
    if (from && !std::isfinite(*from)) {
        throw std::invalid_argument(std::string(from_name) + " " + text(*from) + ": not a finite time");
    }
    if (to && !std::isfinite(*to)) {
        throw std::invalid_argument(std::string(to_name) + " " + text(*to) + ": not a finite time");
    }
    if (from && to && !(*from < *to)) {
        throw std::invalid_argument(std::string("the period is empty: ") + from_name + " " + text(*from) +
                                    " is not before " + to_name + " " + text(*to));
    }
}

void for_each_solution(const std::string& path, const std::function<void(const SolutionRecord&)>& fn,
                       const std::string& label) {
    std::error_code ec;
    const auto size = std::filesystem::file_size(path, ec);
    BlockReader blocks(path);
    std::string_view block;
    if (!blocks.next(block)) {
        throw InputError(path, 1, 1, "empty file: expected a header line");
    }
    const std::size_t nl = block.find('\n');
    const SolutionsReader header(path, block.substr(0, nl));
    block = nl == std::string_view::npos ? std::string_view() : block.substr(nl + 1);
    std::size_t lines_before = 1;
    double done_bytes = static_cast<double>(nl == std::string_view::npos ? 0 : nl + 1);
    Progress progress(label + ": reading " + path);
    SolutionRecord rec;
    for (;;) {
        SolutionsReader reader(header, block, lines_before);
        while (reader.next(rec)) {
            fn(rec);
        }
        done_bytes += static_cast<double>(block.size());
        if (!ec && size > 0) {
            progress.update(done_bytes / static_cast<double>(size));
        }
        if (!blocks.next(block)) {
            break;
        }
        lines_before = blocks.lines_before();
    }
}

}  // namespace ascorr::host
