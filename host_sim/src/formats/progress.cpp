#include "ascorr_host/formats/progress.hpp"

#include <unistd.h>

#include <cstdio>
#include <utility>

#include "ascorr_text/c_format.hpp"

namespace ascorr::host {

Progress::Progress(std::string label) : label_(std::move(label)), enabled_(::isatty(STDERR_FILENO) == 1) {}

Progress::~Progress() {
    done();
}

void Progress::update(double fraction) {
    if (!enabled_) {
        return;
    }
    const int pct = fraction <= 0.0 ? 0 : fraction >= 1.0 ? 100 : static_cast<int>(fraction * 100.0);
    if (pct != shown_) {
        shown_ = pct;
        text::c_fprintf(stderr, "\r%s: %3d%%", label_.c_str(), pct);
        std::fflush(stderr);
    }
}

void Progress::done() {
    if (enabled_ && shown_ >= 0) {
        text::c_fprintf(stderr, "\r%*s\r", static_cast<int>(label_.size()) + 6, "");
        std::fflush(stderr);
        shown_ = -1;
    }
}

}  // namespace ascorr::host
