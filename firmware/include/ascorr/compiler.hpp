// ascorr/compiler.hpp: forwarding header, kept so that existing includes keep
// working; the header is ascorr/core/compiler.hpp.
#pragma once

#include "core/compiler.hpp"
