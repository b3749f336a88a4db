// ascorr/model_coefficients.hpp: forwarding header, kept so that existing includes keep
// working; the header is ascorr/core/model_coefficients.hpp.
#pragma once

#include "core/model_coefficients.hpp"
