// ascorr/constants.hpp: forwarding header, kept so that existing includes keep
// working; the header is ascorr/core/constants.hpp.
#pragma once

#include "core/constants.hpp"
