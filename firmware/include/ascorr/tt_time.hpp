// ascorr/tt_time.hpp: forwarding header, kept so that existing includes keep
// working; the header is ascorr/nav/tt_time.hpp.
#pragma once

#include "nav/tt_time.hpp"
