#include "ascorr_host/analysis/epochs.hpp"

#include <cmath>
#include <cstdio>
#include <stdexcept>

#include "ascorr_text/c_format.hpp"

namespace ascorr::host {

void refuse_bad_time_range(const std::optional<double>& from, const std::optional<double>& to, const char* from_name,
                           const char* to_name) {
    const auto text = [](double x) {
        char buf[48];
        text::c_snprintf(buf, sizeof buf, "%.17g", x);
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

}  // namespace ascorr::host
