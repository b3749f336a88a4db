// ascorr_hal/interface.hpp: the base of the HAL's device interfaces.
//
// A device (a clock, GPIO lines, an ADC, a sample-set source) is a resource, not a
// value: copying one would duplicate its state (a bus position, a replay
// cursor, a time) behind the caller's back. Every interface derives from
// Interface, which deletes copy and move; implementations are used through
// references and pointers, as F Prime's ports are. Freestanding.
#pragma once

namespace ascorr::hal {

class Interface {
public:
    Interface(const Interface&) = delete;
    Interface& operator=(const Interface&) = delete;
    Interface(Interface&&) = delete;
    Interface& operator=(Interface&&) = delete;

protected:
    Interface() = default;
    ~Interface() = default;
};

}  // namespace ascorr::hal
