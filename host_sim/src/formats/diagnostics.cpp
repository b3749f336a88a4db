#include "ascorr_host/formats/diagnostics.hpp"

namespace ascorr::host {

void Diagnostics::report(const std::string& kind, const std::string& message) {
    const std::size_t n = ++counts_[kind];
    if (n <= limit_) {
        out_ << message << '\n';
    }
}

void Diagnostics::summarize() {
    for (const auto& [kind, n] : counts_) {
        if (n > limit_) {
            out_ << "ascorr: " << (n - limit_) << " more '" << kind << "' messages not shown (" << n << " in all)\n";
        }
    }
}

std::size_t Diagnostics::count(const std::string& kind) const {
    const auto it = counts_.find(kind);
    return it == counts_.end() ? 0 : it->second;
}

std::size_t Diagnostics::total() const {
    std::size_t n = 0;
    for (const auto& kv : counts_) {
        n += kv.second;
    }
    return n;
}

}  // namespace ascorr::host
