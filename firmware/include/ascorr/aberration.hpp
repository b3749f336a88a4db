// ascorr/aberration.hpp: forwarding header, kept so that existing includes keep
// working; the header is ascorr/core/aberration.hpp.
#pragma once

#include "core/aberration.hpp"
