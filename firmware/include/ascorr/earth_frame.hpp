// ascorr/earth_frame.hpp: forwarding header, kept so that existing includes keep
// working; the header is ascorr/nav/earth_frame.hpp.
#pragma once

#include "nav/earth_frame.hpp"
