// ascorr/quaternion.hpp: forwarding header, kept so that existing includes keep
// working; the header is ascorr/core/quaternion.hpp.
#pragma once

#include "core/quaternion.hpp"
