// ascorr/heads.hpp: forwarding header, kept so that existing includes keep
// working; the header is ascorr/core/heads.hpp.
#pragma once

#include "core/heads.hpp"
