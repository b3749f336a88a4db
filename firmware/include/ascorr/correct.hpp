// ascorr/correct.hpp: forwarding header, kept so that existing includes keep
// working; the header is ascorr/core/correct.hpp.
#pragma once

#include "core/correct.hpp"
