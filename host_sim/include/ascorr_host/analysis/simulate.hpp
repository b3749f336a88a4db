// ascorr_host/analysis/simulate.hpp: a Swarm-like recorded data set (`ascorr simulate`).
//
// Conventions:
//  - Orbit: circular, altitude 460 km, inclination 87.4°, GCRS axes (no
//    precession: the data span a few years and only directions relative to the
//    stars and the Sun matter). The node drifts so that the orbital plane
//    turns against the Sun once per kPlaneSunPeriodDays (Swarm Alpha: 267 d).
//  - Body frame (orbital frame, spacecraft fixed in it): x along the velocity,
//    z to nadir, y = z × x. R_body_icrf has rows x, y, z in ICRF.
//  - Heads: boresights 54.7° from the zenith at azimuths 90° (A), 210° (B),
//    330° (C) from +x towards +y, hence mutually 90° apart. head_mounting(h)
//    maps body into head components, so q_chu_icrf = R_head_body·R_body_icrf.
//  - Truth: the rigid attitude. The head really points along the deformed,
//    noisy attitude q_meas = q_th* ⊗ q_noise ⊗ q_true, with q_th the thermal
//    correction of the truth model for the recorded temperatures; the raw
//    solution is q_meas with the aberration correction undone (fixed-point
//    inversion of the core's own aberration rotation). So `ascorr correct`
//    with the truth model returns q_noise ⊗ q_true, and its IBA is the floor.
//  - Heater events (the paper's §3.2 heater test, repeated): every 40–80 days
//    for 3–5 days, alternately the operational heater (the CHUs +2–3 °C and
//    THT00032 +2 °C) and the survival heater (THT00029 +3 °C), each switched
//    on and off with a half-day time constant. Their windows [start, end] (the
//    heater on; the temperatures relax for a few days after) are written
//    beside the data.
//  - The floor: the IBA RMS per pair of q_noise ⊗ q_true over the clean
//    epochs (docs/contract.md), written beside the data.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstddef>
#include <cstdint>
#include <iosfwd>
#include <string>
#include <vector>

#include "ascorr_host/analysis/iba.hpp"

namespace ascorr::host {

inline constexpr double kDefaultSimStartT = 456148800.0;  // 2014-06-16T00:00 TT, s since J2000
inline constexpr double kPlaneSunPeriodDays = 267.0;
inline constexpr double kSimAltitudeKm = 460.0;
inline constexpr double kSimInclinationDeg = 87.4;

struct SimulateOptions {
    std::string out;
    double days = 920.0;  // 2.5 years
    double step_s = 60.0;
    std::uint64_t seed = 1;
    std::string truth;  // model file; empty: the embedded Table 2
    double start_t = kDefaultSimStartT;
};

struct HeaterEvent {
    double start = 0.0;        // heater on, s since J2000 TT
    double end = 0.0;          // heater off
    bool operational = false;  // false: the survival heater
};

struct SimulateSummary {
    std::size_t epochs = 0;
    std::size_t rows = 0;
    std::array<std::size_t, 3> outage_rows{};  // per head, not written (Sun or Moon in view)
    std::size_t flagged_rows = 0;              // flags != 0 or confidence > 5
    std::size_t rows_without_temperature = 0;
    std::size_t rows_without_velocity = 0;
    std::array<Rms, kPairs> floor{};
    std::string truth_path;
    std::string floor_path;
    std::vector<HeaterEvent> heaters;  // those starting before the last epoch
    std::string heaters_path;
};

// Writes opt.out, opt.out + ".truth.csv", opt.out + ".floor.json" and
// opt.out + ".heaters.csv" (start,end,heater: operational or survival).
// Throws std::invalid_argument for bad options, InputError for a bad truth file.
SimulateSummary simulate(const SimulateOptions& opt);

// Body into head components for head 0..2 (A, B, C).
Eigen::Matrix3d head_mounting(int head);

std::string describe(const SimulateSummary& s);
std::string floor_json(const std::array<Rms, kPairs>& floor);
std::string heaters_csv(const std::vector<HeaterEvent>& events);

}  // namespace ascorr::host
