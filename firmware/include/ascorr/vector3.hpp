// ascorr/vector3.hpp: forwarding header, kept so that existing includes keep
// working; the header is ascorr/core/vector3.hpp.
#pragma once

#include "core/vector3.hpp"
