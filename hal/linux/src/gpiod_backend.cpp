// The libgpiod backend (gpiod_backend.hpp).
#include "ascorr_hal_linux/gpiod_backend.hpp"

#include <time.h>

#include <cerrno>

#include <gpiod.hpp>
#include <stdexcept>
#include <string>
#include <system_error>

namespace ascorr::hal {

std::uint64_t SteadyClock::now_us() noexcept {
    return static_cast<std::uint64_t>(
        std::chrono::duration_cast<std::chrono::microseconds>(std::chrono::steady_clock::now().time_since_epoch())
            .count());
}

void SteadyClock::wait_us(std::uint32_t us) noexcept {
    timespec ts{static_cast<time_t>(us / 1000000U), static_cast<long>(us % 1000000U) * 1000L};
    // Resume after signals (EINTR) only; any other error ends the wait.
    while (::nanosleep(&ts, &ts) != 0 && errno == EINTR) {
    }
}

struct GpiodPins::Lines {
    gpiod::chip chip;
    gpiod::line cs;
    gpiod::line clk;
    gpiod::line mosi;
    gpiod::line miso;
};

namespace {

gpiod::line request(const gpiod::chip& chip, const std::string& chip_name, unsigned offset, const char* what, int type,
                    int initial) {
    const std::string where = chip_name + ": line " + std::to_string(offset) + " (" + what + ")";
    try {
        gpiod::line l = chip.get_line(offset);
        l.request({"ascorr", type, 0}, initial);
        return l;
    } catch (const std::system_error& e) {
        throw std::system_error(e.code(), "cannot request " + where);
    } catch (const std::exception& e) {  // std::out_of_range: no such offset on this chip
        throw std::runtime_error("cannot request " + where + ": " + e.what());
    }
}

bool put(const gpiod::line& l, bool level) noexcept {
    try {
        l.set_value(level ? 1 : 0);
        return true;
    } catch (...) {
        return false;
    }
}

}  // namespace

GpiodPins::GpiodPins(const GpioWiring& w) : lines_(std::make_unique<Lines>()) {
    try {
        lines_->chip.open(w.chip);
    } catch (const std::system_error& e) {
        throw std::system_error(e.code(), "cannot open GPIO chip '" + w.chip + "'");
    }
    lines_->cs = request(lines_->chip, w.chip, w.cs, "CS", gpiod::line_request::DIRECTION_OUTPUT, 1);
    lines_->clk = request(lines_->chip, w.chip, w.clk, "CLK", gpiod::line_request::DIRECTION_OUTPUT, 0);
    lines_->mosi = request(lines_->chip, w.chip, w.mosi, "MOSI", gpiod::line_request::DIRECTION_OUTPUT, 0);
    lines_->miso = request(lines_->chip, w.chip, w.miso, "MISO", gpiod::line_request::DIRECTION_INPUT, 0);
}

GpiodPins::~GpiodPins() {
    for (gpiod::line* l : {&lines_->cs, &lines_->clk, &lines_->mosi, &lines_->miso}) {
        try {
            if (l->is_requested()) {
                l->release();
            }
        } catch (...) {
            // Releasing cannot fail in a way we could act on; the kernel
            // frees the lines when the chip is closed anyway.
        }
    }
}

bool GpiodPins::set_cs(bool level) noexcept {
    return put(lines_->cs, level);
}
bool GpiodPins::set_clk(bool level) noexcept {
    return put(lines_->clk, level);
}
bool GpiodPins::set_mosi(bool level) noexcept {
    return put(lines_->mosi, level);
}
bool GpiodPins::get_miso(bool& level) noexcept {
    try {
        level = lines_->miso.get_value() != 0;
        return true;
    } catch (...) {
        return false;
    }
}

GpiodSampleSetSource::GpiodSampleSetSource(const HalConfig& config, Clock& clock)
    : config_(config),
      pins_(config_.gpio),
      adc_(pins_, clock, config_.gpio.half_period_us),
      source_(adc_, clock, config_.acquisition) {}

}  // namespace ascorr::hal
