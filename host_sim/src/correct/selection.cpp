#include "ascorr_host/correct/selection.hpp"

namespace ascorr::host {

Drop fit_selection(const SolutionRecord& rec) noexcept {
    if ((rec.flags & 1) != 0) {
        return Drop::kHighRate;
    }
    if ((rec.flags & 2) != 0) {
        return Drop::kBrightObject;
    }
    if ((rec.flags & 4) != 0) {
        return Drop::kInvalid;
    }
    if (!confidence_clean(rec)) {
        return Drop::kConfidence;
    }
    if (!(rec.temperature_present[0] && rec.temperature_present[1] && rec.temperature_present[2])) {
        return Drop::kTemperature;
    }
    if (rec.velocity_components != 3) {
        return Drop::kVelocity;
    }
    return Drop::kNone;
}

const char* drop_name(Drop d) noexcept {
    switch (d) {
        case Drop::kNone:
            return "selected";
        case Drop::kHighRate:
            return "high-rate mode";
        case Drop::kBrightObject:
            return "bright object";
        case Drop::kInvalid:
            return "invalid";
        case Drop::kConfidence:
            return "confidence > 5 or missing";
        case Drop::kTemperature:
            return "temperature missing";
        case Drop::kVelocity:
            return "velocity missing";
        case Drop::kRejected:
            return "not correctable";
    }
    return "?";
}

}  // namespace ascorr::host
