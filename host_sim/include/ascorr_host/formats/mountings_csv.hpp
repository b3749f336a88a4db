// ascorr_host/formats/mountings_csv.hpp: the mountings file (docs/contract.md, "Combined attitude").
//
// Header chu,qw,qx,qy,qz and optionally sigma_cross,sigma_about (both or
// neither); one row per head. q is q_chu_crf (v_chu = R(q) v_crf, so
// R(q_chu_icrf) = R(q_chu_crf) R(q_crf_icrf)); sigma_cross is the head's 1σ
// noise per axis across its boresight, sigma_about about it, in arcsec.
//
// Every refusal is an InputError at file:line:column, found before any data
// is read: an unknown or missing column, a head letter that is not one of
// heads.hpp's, an empty chu (a missing head), a head twice, a quaternion
// field empty or not a finite number, a quaternion that is zero or not unit
// (|‖q‖² − 1| > combine::kMountingNormTolerance, the core's tolerance for
// solutions), a sigma that is NaN, infinite, zero, negative or outside
// [combine::kMinSigmaArcsec, kMaxSigmaArcsec], sigmas on some rows only (a
// row gives both or none, and every row alike), a file without rows. The
// limits are combine/mountings.hpp's; what only the head set shows (an
// ill-conditioned subset) is combine::check_mountings', which
// refuse_unusable_mountings() (analysis/combine.hpp) reports at the head's line.
#pragma once

#include <array>
#include <cstddef>
#include <string>
#include <string_view>

#include "ascorr/combine/mountings.hpp"
#include "ascorr/core/heads.hpp"

namespace ascorr::host {

struct MountingsFile {
    combine::Mountings mountings{};  // sigmas NaN when the file has none
    bool sigmas = false;             // every row gives sigma_cross and sigma_about
    // Where each head was read (1-based line; 0 for mountings not read from a file).
    std::array<std::size_t, kMaxHeads> line{};
};

MountingsFile read_mountings_file(const std::string& path);
MountingsFile parse_mountings(const std::string& file_name, std::string_view text);

// The file's text: the heads present in heads.hpp's order, numbers in the
// shortest text that reads back exactly; the sigma columns when m.sigmas.
std::string format_mountings(const MountingsFile& m);
// Writes atomically (temporary file, then rename).
void write_mountings_file(const std::string& path, const MountingsFile& m);

}  // namespace ascorr::host
