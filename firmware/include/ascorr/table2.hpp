// ascorr/table2.hpp: forwarding header, kept so that existing includes keep
// working; the header is ascorr/core/table2.hpp.
#pragma once

#include "core/table2.hpp"
