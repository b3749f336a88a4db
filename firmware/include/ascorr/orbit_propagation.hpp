// ascorr/orbit_propagation.hpp: forwarding header, kept so that existing includes keep
// working; the header is ascorr/nav/orbit_propagation.hpp.
#pragma once

#include "nav/orbit_propagation.hpp"
