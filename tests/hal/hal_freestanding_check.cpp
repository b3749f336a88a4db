// Build-time check: the HAL's firmware part compiles without exceptions and
// RTTI, for float (the DPU's scalar), double and the fixed-point QCelsius
// (fixed_thermistor.hpp), as the bare-metal build will compile it. Nothing
// here runs; the build failing is the test.
#include "ascorr_hal/acquisition.hpp"
#include "ascorr_hal/fixed_thermistor.hpp"
#include "ascorr_hal/mcp3208.hpp"
#include "ascorr_hal/sample_set.hpp"
#include "ascorr_hal/sampler.hpp"

template class ascorr::hal::TemperatureAcquisition<float>;
template class ascorr::hal::TemperatureAcquisition<double>;
template class ascorr::hal::AdcSampleSetSource<float>;
template class ascorr::hal::ChannelCheck<float>;
template class ascorr::hal::TemperatureAcquisition<ascorr::QCelsius>;
template class ascorr::hal::AdcSampleSetSource<ascorr::QCelsius>;
template class ascorr::hal::ChannelCheck<ascorr::QCelsius>;

// The device interfaces (and so every implementation) are neither copyable nor
// movable (ascorr_hal/interface.hpp).
#include <type_traits>
namespace hal_interface_check {
using namespace ascorr::hal;
template <typename I>
constexpr bool resource_like = !std::is_copy_constructible_v<I> && !std::is_copy_assignable_v<I> &&
                               !std::is_move_constructible_v<I> && !std::is_move_assignable_v<I>;
static_assert(resource_like<Clock> && resource_like<ManualClock>);
static_assert(resource_like<BitBangPins> && resource_like<AdcPort> && resource_like<Mcp3208>);
static_assert(resource_like<SampleSetSource<float>> && resource_like<AdcSampleSetSource<float>>);
}  // namespace hal_interface_check
