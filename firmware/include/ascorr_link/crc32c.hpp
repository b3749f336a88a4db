// ascorr_link/crc32c.hpp: the link's frame CRC is the firmware's CRC-32C
// (ascorr/crc32c.hpp), shared with the thermal model's identity.
#pragma once

#include "../ascorr/crc32c.hpp"

namespace ascorr::link {

using ascorr::crc32c;

}  // namespace ascorr::link
