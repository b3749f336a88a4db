// ascorr/fixed_point.hpp: forwarding header, kept so that existing includes keep
// working; the header is ascorr/core/fixed_point.hpp.
#pragma once

#include "core/fixed_point.hpp"
