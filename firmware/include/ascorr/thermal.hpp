// ascorr/thermal.hpp: forwarding header, kept so that existing includes keep
// working; the header is ascorr/core/thermal.hpp.
#pragma once

#include "core/thermal.hpp"
