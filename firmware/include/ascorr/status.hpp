// ascorr/status.hpp: forwarding header, kept so that existing includes keep
// working; the header is ascorr/core/status.hpp.
#pragma once

#include "core/status.hpp"
