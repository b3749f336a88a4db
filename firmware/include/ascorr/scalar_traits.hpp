// ascorr/scalar_traits.hpp: forwarding header, kept so that existing includes keep
// working; the header is ascorr/core/scalar_traits.hpp.
#pragma once

#include "core/scalar_traits.hpp"
