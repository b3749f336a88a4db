// Proof that the core never allocates: global operator new/delete are
// replaced by counting versions and malloc/calloc/realloc wrapped (link-time,
// alloc_counter.cpp), and the core is run over good and bad input in every
// scalar type (double, float, Q30) with the counter armed.
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

// Runs the core over n good and bad solutions with the counter armed. The
// inputs are made in double and converted as a DPU is given them
// (ScalarTraits<T>), so the same code serves double, float and Q30.
template <typename T>
long allocations_while_correcting(int n) {
    using Tr = ScalarTraits<T>;
    ThermalModel<T> model{};
    for (auto& h : model.head) {
        h.present = true;
        h.gamma.c0 = Tr::coefficient(1e-4);
        h.alpha.c1 = Tr::coefficient(1e-6);
        h.beta.c2_2 = Tr::quadratic_coefficient(1e-9);
    }
    const double nan = std::numeric_limits<double>::quiet_NaN();
    std::mt19937 rng(5);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    arm_allocation_counter();
    double sink = 0;
    for (int i = 0; i < n; ++i) {
        SolutionInput<T> in{};
        const double a = u(rng);
        in.q_chu_icrf = {Tr::from_double(0.6), Tr::from_double(0.8 * a), Tr::from_double(0.8 * std::sqrt(1.0 - a * a)),
                         Tr::from_double(0.0)};
        in.head = static_cast<std::uint8_t>(i % 6);  // includes out-of-range heads
        in.temperatures = {{Tr::celsius(20.0), i % 5 != 0},
                           {Tr::celsius(i % 7 == 0 ? nan : -5.0), true},
                           {Tr::celsius(i % 17 == 0 ? 900.0 : -20.0), true}};
        in.velocity = {{Tr::from_double(1e-4 * a), Tr::from_double(i % 11 == 0 ? 2.0 : 0.0), Tr::from_double(0.0)},
                       Tr::from_double(i % 19 == 0 ? 1e9 : 1.0),
                       i % 3 != 0};
        if (i % 13 == 0) {
            in.q_chu_icrf.w = Tr::from_double(nan);
        }
        const auto out = correct_solution(in, CorrectionConfig<T>{true, &model});
        sink += Tr::to_double(out.q_chu_icrf.w) + static_cast<double>(out.status);
    }
    const long allocations = disarm_allocation_counter();
    g_sink = sink;  // keep the work observable to the optimiser
    return allocations;
}

// The hooks work, so a zero below means something: operator new, malloc,
// calloc and realloc are each counted (alloc_counter.cpp).
TEST(NoAllocation, CounterSeesEveryKindOfAllocation) {
    arm_allocation_counter();
    auto* p = new int(3);
    g_escape = p;  // observable, so the compiler may not elide the new/delete pair
    void* volatile m = std::malloc(16);
    void* volatile c = std::calloc(4, 4);
    void* volatile r = std::realloc(nullptr, 8);
    const long allocations = disarm_allocation_counter();
    delete p;
    std::free(m);
    std::free(c);
    std::free(r);
    EXPECT_EQ(allocations, 4);
}

TEST(NoAllocation, DoubleCore) {
    EXPECT_EQ(allocations_while_correcting<double>(100000), 0);
}
TEST(NoAllocation, FloatCore) {
    EXPECT_EQ(allocations_while_correcting<float>(100000), 0);
}
TEST(NoAllocation, FixedPointCore) {
    EXPECT_EQ(allocations_while_correcting<Q30>(100000), 0);
}

}  // namespace
}  // namespace ascorr::test
