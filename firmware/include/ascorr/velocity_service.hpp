// ascorr/velocity_service.hpp: forwarding header, kept so that existing includes keep
// working; the header is ascorr/nav/velocity_service.hpp.
#pragma once

#include "nav/velocity_service.hpp"
