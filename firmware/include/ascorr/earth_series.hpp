// ascorr/earth_series.hpp: forwarding header, kept so that existing includes keep
// working; the header is ascorr/nav/earth_series.hpp.
#pragma once

#include "nav/earth_series.hpp"
