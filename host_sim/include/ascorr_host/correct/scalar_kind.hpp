// ascorr_host/correct/scalar_kind.hpp: which scalar the core is instantiated
// with, the one name for it on the host: `ascorr correct --scalar`, the Python
// module's scalar= argument, the boards of `ascorr replay` (qemu_targets.hpp)
// and the tests. A kind, not the type: the firmware's type is
// firmware/app/app_scalar.hpp's Scalar, and a target reports its kind in the
// link's HELLO (scalar_kind, ascorr_link/messages.hpp's WireTraits<T>::kKind).
#pragma once

#include <array>
#include <optional>
#include <string_view>
#include <type_traits>

#include "ascorr/core/q_formats.hpp"

namespace ascorr::host {

enum class ScalarKind { kDouble, kFloat, kFixed };  // double, float, Q30

struct ScalarName {
    std::string_view name;
    ScalarKind kind;
};

// The names, lower case, in the order the command line and Python list them.
inline constexpr std::array<ScalarName, 3> kScalarNames = {
    {{"double", ScalarKind::kDouble}, {"float", ScalarKind::kFloat}, {"fixed", ScalarKind::kFixed}}};

constexpr std::string_view scalar_name(ScalarKind kind) noexcept {
    for (const ScalarName& n : kScalarNames) {
        if (n.kind == kind) {
            return n.name;
        }
    }
    return "?";
}

// The kind of a lower-case name; std::nullopt for any other text (the callers
// fold the case first: names are case-insensitive).
constexpr std::optional<ScalarKind> scalar_from_name(std::string_view name) noexcept {
    for (const ScalarName& n : kScalarNames) {
        if (n.name == name) {
            return n.kind;
        }
    }
    return std::nullopt;
}

// The kind of a core scalar type (double, float, Q30).
template <typename T>
constexpr ScalarKind scalar_kind_of() noexcept {
    static_assert(std::is_same_v<T, double> || std::is_same_v<T, float> || std::is_same_v<T, Q30>, "a core scalar");
    return std::is_same_v<T, double> ? ScalarKind::kDouble
                                     : (std::is_same_v<T, float> ? ScalarKind::kFloat : ScalarKind::kFixed);
}

}  // namespace ascorr::host
