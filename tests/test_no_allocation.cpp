// Proof that the core never allocates: global operator new/delete are
// replaced by counting versions, and the core is run over good and bad input
// in both scalar types with the counter armed.
#include <gtest/gtest.h>

#include <cstdlib>
#include <limits>
#include <new>
#include <random>
#include <type_traits>

#include "alloc_counter.hpp"
#include "ascorr/ascorr.hpp"

namespace ascorr::test {
namespace {

volatile double g_sink = 0.0;
int* volatile g_escape = nullptr;

static_assert(std::is_trivially_copyable_v<SolutionInput<double>>);
static_assert(std::is_trivially_copyable_v<ThermalModel<float>>);
static_assert(std::is_trivially_copyable_v<CorrectedSolution<float>>);
static_assert(noexcept(correct_solution(std::declval<const SolutionInput<double>&>(),
                                        std::declval<const CorrectionConfig<double>&>())));
// Unaligned, fixed-size types: nothing over-aligned that would need aligned new.
static_assert(alignof(ThermalModel<double>) == alignof(double));
static_assert(alignof(Quaternion<float>) == alignof(float));

template <typename T>
long allocations_while_correcting(int n) {
    ThermalModel<T> model{};
    for (auto& h : model.head) {
        h.present = true;
        h.gamma.c0 = static_cast<T>(1e-4);
        h.alpha.c1 = static_cast<T>(1e-6);
    }
    const T nan = std::numeric_limits<T>::quiet_NaN();
    std::mt19937 rng(5);
    std::uniform_real_distribution<float> u(-1.0F, 1.0F);
    arm_allocation_counter();
    T sink = 0;
    for (int i = 0; i < n; ++i) {
        SolutionInput<T> in{};
        const T a = static_cast<T>(u(rng));
        in.q_chu_icrf = {static_cast<T>(0.6), static_cast<T>(0.8) * a, static_cast<T>(0.8) * std::sqrt(T(1) - a * a),
                         0};
        in.head = static_cast<std::uint8_t>(i % 6);  // includes out-of-range heads
        in.temperatures = {{static_cast<T>(20), i % 5 != 0},
                           {i % 7 == 0 ? nan : static_cast<T>(-5), true},
                           {static_cast<T>(-20), true}};
        in.velocity = {{static_cast<T>(1e-4) * a, static_cast<T>(i % 11 == 0 ? 2.0 : 0.0), 0}, 1, i % 3 != 0};
        if (i % 13 == 0) {
            in.q_chu_icrf.w = nan;
        }
        const auto out = correct_solution(in, CorrectionConfig<T>{true, &model});
        sink += out.q_chu_icrf.w + static_cast<T>(out.status);
    }
    const long allocations = disarm_allocation_counter();
    g_sink = static_cast<double>(sink);  // keep the work observable to the optimiser
    return allocations;
}

TEST(NoAllocation, CounterSeesAllocations) {
    arm_allocation_counter();
    auto* p = new int(3);
    g_escape = p;  // observable, so the compiler may not elide the new/delete pair
    const long allocations = disarm_allocation_counter();
    delete p;
    EXPECT_EQ(allocations, 1);  // the hook works, so a zero below means something
}

TEST(NoAllocation, DoubleCore) {
    EXPECT_EQ(allocations_while_correcting<double>(100000), 0);
}
TEST(NoAllocation, FloatCore) {
    EXPECT_EQ(allocations_while_correcting<float>(100000), 0);
}

}  // namespace
}  // namespace ascorr::test
