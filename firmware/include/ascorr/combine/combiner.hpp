// ascorr/combine/combiner.hpp: one attitude of the bench (CRF) from the heads of one epoch.
//
// Conventions (mountings.hpp, kernels.hpp; the contract's "Combined attitude"):
//  - each head's corrected solution q_chu_icrf_i gives an estimate of the CRF
//    attitude q_crf_icrf_i = q_chu_crf_i* ⊗ q_chu_icrf_i;
//  - the combined attitude is the information-weighted mean of their small
//    rotations about a reference (the first usable head), in CRF axes:
//      θ̄ = (Σ W_i)⁻¹ Σ W_i θ_i,   q_crf_icrf = Exp(θ̄) ⊗ q_ref,
//    with formal covariance (Σ W_i)⁻¹ (subset_tables.hpp; Bandikova & Flury
//    2014, eq. 4; Romans 2003). Weighted least squares for independent heads
//    whose noise is σc across and σa about their boresight;
//  - q_crf_icrf has w ≥ 0; both signs of every input are the same attitude.
//
// Per epoch, for n heads (the usual epoch; the vote and the gate's rounds
// only when a head is off): n quaternion products (the mountings), n − 1
// half-angle differences to the reference, n − 1 gain products (3 × 3), per
// head a quick gate (‖e‖² against a bound of the gate, three squares; the full
// statistic, six products and three squares, only above it), one quaternion
// update and one renormalisation (a Newton step: no division, no square
// root). Every table is built at construction in double (subset_tables.hpp).
// Instructions per epoch of three heads: docs/figures.md.
//
// In parts: combiner_class.hpp (the types and the class), combiner_build.hpp
// (construction), combiner_usual.hpp (the usual epoch in one pass) and
// combiner_general.hpp (steps 1 to 4 below, for any epoch).
//
// Which heads are averaged (in this order):
//  1. Left out, status 4 (not `inconsistent`): an entry whose head index is no
//     head (≥ kMaxHeads; in no mask), a second entry of a head already seen
//     (the first one is kept), an entry the caller marked not usable, a head
//     not in the mountings, and a quaternion that is not unit (the core's
//     tolerance; NaN and infinity included).
//  2. The gross gate (bounded linearisation): every kept head within
//     kGrossAngleRad (2⁻⁸ rad, 806″) of the reference is kept. When one is
//     not, the reference becomes the head within that angle of the most
//     others (the first in input order on a tie); heads farther from it are
//     inconsistent. A head outside the reference's group near as many
//     others (a rival group as large): step 3 decides, the group it keeps
//     more heads of (Combiner::vote). No two heads within the angle of each
//     other, no group consistent, or two that keep as many (e.g. two
//     consistent pairs of four heads): no combination (below).
//  3. The consistency gate, a gross-error gate. Head i's leave-one-out
//     residual r_i = θ_i − θ̂_{S∖i} (its estimate against the others'
//     combination) is normalised by its covariance plus a floor:
//        d_i² = r_iᵀ (C_i + P_{S∖i}⁻¹ + f² I)⁻¹ r_i,
//     and the head is inconsistent when d_i > k (CombinerConfig: k = 6;
//     the floor f by what is known of the rows and the mountings,
//     default_gate, gate_config.hpp). The floor keeps what the heads' noise does not
//     describe inside the gate: with f = 10″ it never trips below k·f = 60″,
//     so not on the differential aberration of raw rows (up to ~29″), the
//     2–3″ of uncorrected deformation, nor pre-flight mountings a few tens of
//     arcsec off; with f = 2″ (both stages, mountings of the ground) a head
//     40″ off across its boresight is caught (tests: CombineGate). With the
//     covariance, not on noise (5σ of one head gives d² ≤ 25 < 36). With
//     σc = 1.3″, σa = 9″ and f = 10″ it surely trips beyond
//     k·sqrt(σa² + σa² + f²) ≈ 97″ (two heads) and ~82″ (three). With three
//     or more heads,
//     of the heads beyond the gate the one whose removal leaves the others
//     most consistent (the smallest largest d² of the rest, each found by the
//     same tables) is left out, and the gate is run again on the rest: at
//     most kMaxHeads − 2 rounds of at most kMaxHeads trials (when the
//     reference goes, the differences are re-formed about the first
//     remaining head). The largest d_i alone is not enough: a good head
//     whose weak axis the bad head's error lies along can score higher. Two heads
//     that fail the gate (first or after a removal): nothing tells which one
//     is wrong, and averaging would put the gross error into the attitude,
//     so there is no combination: both are inconsistent, status 4 | 8, q the
//     identity. A gap with its reason is safer for the user than an attitude
//     that may be hundreds of arcsec off, and it is what the Swarm product
//     does for an epoch without a consistent pair ("not enough data").
//  4. Status: 1 with two or more heads averaged, 2 with one (its formal σ is
//     large about its boresight), 8 with none (q the identity); 4 whenever a
//     head was left out (combined_status.hpp).
#pragma once

#include <cstdint>

#include "combiner_build.hpp"
#include "combiner_class.hpp"
#include "combiner_general.hpp"
#include "combiner_usual.hpp"

namespace ascorr::combine {

template <typename T>
CombinedAttitude<T> Combiner<T>::combine(const HeadAttitude<T>* heads, std::uint8_t n) const noexcept {
    CombinedAttitude<T> out;  // one object, returned in place
    if (!valid() || !combine_usual(heads, n, &out)) {
        out = combine_general(heads, n);
    }
    return out;
}

}  // namespace ascorr::combine
