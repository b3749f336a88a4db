// ascorr/sincos.hpp: forwarding header, kept so that existing includes keep
// working; the header is ascorr/nav/sincos.hpp.
#pragma once

#include "nav/sincos.hpp"
