// tests/target/flight_expectation.cpp: the flight loop's solutions (firmware/
// app/main.cpp under QEMU) against the host core.
//
// Usage: ascorr_flight_expectation_<scalar> check REPORT BOUND_ARCSEC
//        ascorr_flight_expectation_<scalar> print CYCLES
// The host runs the very cycle the DPU runs (FlightCycle, flight_cycle.hpp:
// the recorded GNSS orbit into the velocity service, the raw solutions and
// model of flight_data.hpp, the core in the image's scalar, built with
// ASCORR_APP_FIXED for the Q30 image) for as many cycles as the image's report
// says, with the temperatures of the same HAL acquisition on the same emulated
// boom ADC (boom_temperatures.hpp), timed by a test-double clock instead of
// SysTick: each cycle starts at its nominal time and only the acquisition's
// own waits advance it (on the DPU the instructions executed add
// microseconds, far within the acquisition's margins: boom_temperatures.hpp).
//
// check: compares the image's report (REPORT: its standard output) with the
// host's record (CorrectionLog): per head the cycles with both corrections
// applied, every status bit seen, the last solution, every sample (every
// 16th cycle) and, for BOUND_ARCSEC = 0, the CRC-32C over every cycle's
// solution and status. BOUND_ARCSEC = 0: bit for bit. Otherwise statuses and
// counts exactly, each quaternion within BOUND_ARCSEC of the host's (the
// rotation angle between them). Then the mutation check: the same comparison
// against the host's record with its first sample perturbed (its lowest bit
// of w flipped; with a bound, rotated by twice the bound) must fail, so that
// the check cannot pass vacuously. The image's stack high-water mark
// ("stack: high water N of S bytes", stack_watch.hpp) must be present, at
// least 1 KiB and within three quarters of its size (marks one word beyond
// either bound must fail). Exit 0 when
// all hold, 1 otherwise, every difference named (line, head, cycle, value).
// print: the lines the image prints of its solutions after CYCLES cycles.
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <iostream>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "ascorr_hal/clock.hpp"
#include "boom_temperatures.hpp"
#include "flight_cycle.hpp"
#include "temperature_source.hpp"

namespace ascorr::app {
namespace {

// SysTickClock's behaviour (hal_temperatures.cpp) without the instructions'
// own time: the cycle's nominal start plus the waits done in it, never decreasing.
class CycleClock final : public hal::Clock {
public:
    void start_cycle(std::uint32_t cycle) noexcept {
        base_us_ = static_cast<std::uint64_t>(cycle) * 1000000U / kRateHz;
        waited_us_ = 0U;
    }
    std::uint64_t now_us() noexcept override {
        const std::uint64_t t = base_us_ + waited_us_;
        last_us_ = t > last_us_ ? t : last_us_;
        return last_us_;
    }
    void wait_us(std::uint32_t us) noexcept override { waited_us_ += us; }

private:
    std::uint64_t base_us_ = 0U;
    std::uint64_t waited_us_ = 0U;
    std::uint64_t last_us_ = 0U;
};

CycleClock g_clock;
BoomTemperatures g_temperatures{g_clock};

}  // namespace

// temperature_source.hpp on the host.
void temperatures_update(std::uint32_t cycle) noexcept {
    g_clock.start_cycle(cycle);
    g_temperatures.update(cycle, kRateHz);
}
const HeadTemperatures<Scalar>& temperatures_of(std::uint8_t head) noexcept {
    return g_temperatures.of(head);
}
StatusBits temperatures_merge_status(std::uint8_t head, StatusBits core) noexcept {
    return g_temperatures.merge_status(head, core);
}

}  // namespace ascorr::app

namespace {

using ascorr::kMaxHeads;
using ascorr::kRadToArcsec;
using ascorr::app::CorrectionLog;
// The log's records: the heads, then the combined attitude (CorrectionLog::kCombined).
constexpr unsigned kRecords = CorrectionLog::kRecords;
using ascorr::app::Scalar;

// One corrected solution as printed: status and the components' bit patterns.
struct Printed {
    unsigned status = 0U;
    std::uint32_t bits[4] = {};
};

// What a report says of the solutions.
struct Report {
    std::uint32_t cycles = 0U;
    bool head_seen[kRecords] = {};
    unsigned applied[kRecords] = {};
    unsigned status_seen[kRecords] = {};
    Printed last[kRecords];
    struct Sample {
        unsigned cycle;
        unsigned head;
        Printed s;
    };
    std::vector<Sample> samples;
    bool crc_seen[kRecords] = {};
    unsigned crc_cycles[kRecords] = {};
    std::uint32_t crc[kRecords] = {};
    // The estimator's model history (flight_cycle.hpp ModelHistory).
    struct Model {
        unsigned version = 0U;
        unsigned cycle = 0U;
        std::uint32_t crc = 0U;
        std::uint64_t bits[ascorr::kMaxHeads][ascorr::kModelAxes][ascorr::kLinearModelTerms] = {};
        bool row_seen[ascorr::kMaxHeads][ascorr::kModelAxes] = {};
    };
    std::vector<Model> models;
    // The Sun learner's state ("sun learner: ...", cycle_log.hpp).
    struct Sun {
        bool seen = false;
        unsigned cycles = 0U;
        unsigned orbits = 0U;
        unsigned thinned = 0U;
        unsigned candidate_orbits = 0U;
        unsigned rank = 0U;
        unsigned taken = 0U;
        std::uint32_t crc = 0U;
    } sun;
    // The stack's high-water mark (main.cpp, stack_watch.hpp).
    struct Stack {
        bool seen = false;
        unsigned used = 0U;
        unsigned size = 0U;
    } stack;
};

Printed printed(const ascorr::CorrectedSolution<Scalar>& c) {
    using ascorr::app::bits_of;
    return {c.status,
            {bits_of(c.q_chu_icrf.w), bits_of(c.q_chu_icrf.x), bits_of(c.q_chu_icrf.y), bits_of(c.q_chu_icrf.z)}};
}

Report from_record(const CorrectionLog& r, std::uint32_t cycles) {
    Report out;
    out.cycles = cycles;
    for (std::uint8_t h = 0; h < kRecords; ++h) {
        const CorrectionLog::Head& hd = r.head(h);
        out.head_seen[h] = true;
        out.applied[h] = hd.applied;
        out.status_seen[h] = hd.status_union;
        out.last[h] = printed(hd.last);
        out.crc_seen[h] = true;
        out.crc_cycles[h] = hd.solutions;
        out.crc[h] = hd.crc;
    }
    for (std::uint32_t i = 0; i < r.samples_taken(); ++i) {
        for (std::uint8_t h = 0; h < kRecords; ++h) {
            out.samples.push_back({i * CorrectionLog::kSampleEvery, h, printed(r.sample(i, h))});
        }
    }
    return out;
}

void add_history(const ascorr::app::ModelHistory& hist, Report& out) {
    for (std::uint32_t i = 0; i < hist.size(); ++i) {
        const ascorr::app::ModelHistory::Entry& e = hist.entry(i);
        Report::Model m;
        m.version = e.version;
        m.cycle = e.cycle;
        m.crc = e.crc;
        for (std::size_t h = 0; h < ascorr::kMaxHeads; ++h) {
            for (std::size_t a = 0; a < ascorr::kModelAxes; ++a) {
                m.row_seen[h][a] = true;
                for (std::size_t t = 0; t < ascorr::kLinearModelTerms; ++t) {
                    std::memcpy(&m.bits[h][a][t], &e.model.coefficient[h][a][t], sizeof(double));
                }
            }
        }
        out.models.push_back(m);
    }
}

// The combined attitude's lines as the heads' (record kRecords − 1):
// "combined: ..." → "head N: ...", "sample cycle C combined status" →
// "... head N status", "solutions combined cycles" → "solutions head N cycles".
std::string as_head_line(std::string line) {
    const std::string record = "head " + std::to_string(CorrectionLog::kCombined);
    const std::pair<std::string, std::string> forms[] = {{"combined: ", record + ": "},
                                                         {" combined status ", " " + record + " status "},
                                                         {"solutions combined ", "solutions " + record + " "}};
    for (const auto& [from, to] : forms) {
        if (const std::size_t at = line.find(from); at != std::string::npos) {
            line.replace(at, from.size(), to);
            break;
        }
    }
    return line;
}

bool parse_report(const std::string& path, Report& out) {
    std::ifstream in(path);
    if (!in) {
        std::cerr << path << ": cannot open\n";
        return false;
    }
    std::string line;
    for (int n = 1; std::getline(in, line); ++n) {
        line = as_head_line(line);
        unsigned h = 0U;
        unsigned a = 0U;
        unsigned st = 0U;
        unsigned c = 0U;
        unsigned cycles = 0U;
        Printed p;
        char rest = 0;
        if (std::sscanf(line.c_str(), "%*[^,], %u cycles at", &cycles) == 1 &&
            line.find(" core, ") != std::string::npos) {
            out.cycles = cycles;
        } else if (std::sscanf(line.c_str(), "head %u: applied %u status seen %u last q %8x %8x %8x %8x%c", &h, &a, &st,
                               &p.bits[0], &p.bits[1], &p.bits[2], &p.bits[3], &rest) == 7 &&
                   h < kRecords) {
            out.head_seen[h] = true;
            out.applied[h] = a;
            out.status_seen[h] = st;
            p.status = st;
            out.last[h] = p;
        } else if (std::sscanf(line.c_str(), "sample cycle %u head %u status %u q %8x %8x %8x %8x%c", &c, &h, &p.status,
                               &p.bits[0], &p.bits[1], &p.bits[2], &p.bits[3], &rest) == 7 &&
                   h < kRecords) {
            out.samples.push_back({c, h, p});
        } else if (std::sscanf(line.c_str(), "solutions head %u cycles %u crc32c %8x%c", &h, &c, &p.bits[0], &rest) ==
                       3 &&
                   h < kRecords) {
            out.crc_seen[h] = true;
            out.crc_cycles[h] = c;
            out.crc[h] = p.bits[0];
        } else if (std::sscanf(line.c_str(), "model version %u from cycle %u crc32c %8x%c", &a, &c, &p.bits[0],
                               &rest) == 3) {
            Report::Model m;
            m.version = a;
            m.cycle = c;
            m.crc = p.bits[0];
            out.models.push_back(m);
        } else if (unsigned long long w[4] = {};
                   std::sscanf(line.c_str(), "model version %u head %u axis %u c %16llx %16llx %16llx %16llx%c", &a, &h,
                               &c, &w[0], &w[1], &w[2], &w[3], &rest) == 7 &&
                   h < ascorr::kMaxHeads && c < ascorr::kModelAxes && !out.models.empty() &&
                   out.models.back().version == a) {
            for (std::size_t t = 0; t < ascorr::kLinearModelTerms; ++t) {
                out.models.back().bits[h][c][t] = w[t];
            }
            out.models.back().row_seen[h][c] = true;
        } else if (Report::Sun s;
                   std::sscanf(line.c_str(),
                               "sun learner: cycles %u orbits %u thinned %u candidate orbits %u rank %u taken %u "
                               "crc32c %8x%c",
                               &s.cycles, &s.orbits, &s.thinned, &s.candidate_orbits, &s.rank, &s.taken, &s.crc,
                               &rest) == 7) {
            s.seen = true;
            out.sun = s;
        } else if (std::sscanf(line.c_str(), "stack: high water %u of %u bytes%c", &a, &c, &rest) == 2) {
            out.stack = {true, a, c};
        } else if (line.rfind("head ", 0) == 0 || line.rfind("sample ", 0) == 0 || line.rfind("solutions ", 0) == 0 ||
                   line.rfind("model ", 0) == 0 || line.rfind("sun learner: cycles", 0) == 0 ||
                   line.rfind("stack: ", 0) == 0) {
            std::cerr << path << ":" << n << ": malformed line: " << line << "\n";
            return false;
        }
    }
    if (out.cycles == 0U) {
        std::cerr << path << ": no \"core, N cycles at\" line: not a flight loop report\n";
        return false;
    }
    return true;
}

double value(std::uint32_t bits) {
    if constexpr (std::is_same_v<Scalar, float>) {
        float f = 0.0F;
        std::memcpy(&f, &bits, sizeof f);
        return static_cast<double>(f);
    } else {
        return static_cast<double>(static_cast<std::int32_t>(bits)) / 1073741824.0;  // Q30: raw·2⁻³⁰
    }
}

// The rotation angle between two printed quaternions, arcsec (sign-blind: q and −q are one rotation).
double angle_arcsec(const Printed& a, const Printed& b) {
    double qa[4];
    double qb[4];
    for (int i = 0; i < 4; ++i) {
        qa[i] = value(a.bits[i]);
        qb[i] = value(b.bits[i]);
    }
    // conj(a) ⊗ b: scalar part and vector part.
    const double w = qa[0] * qb[0] + qa[1] * qb[1] + qa[2] * qb[2] + qa[3] * qb[3];
    const double x = qa[0] * qb[1] - qa[1] * qb[0] - qa[2] * qb[3] + qa[3] * qb[2];
    const double y = qa[0] * qb[2] + qa[1] * qb[3] - qa[2] * qb[0] - qa[3] * qb[1];
    const double z = qa[0] * qb[3] - qa[1] * qb[2] + qa[2] * qb[1] - qa[3] * qb[0];
    return 2.0 * std::atan2(std::sqrt(x * x + y * y + z * z), std::fabs(w)) * kRadToArcsec;
}

std::string hex(std::uint32_t v) {
    char b[9];
    std::snprintf(b, sizeof b, "%08x", v);
    return b;
}

struct Outcome {
    int differences = 0;
    int identical = 0;  // quaternions bit for bit
    int compared = 0;   // quaternions
    double worst = 0.0;
};

// One quaternion and its status: `what` names it in a message (printed when `loud`).
void compare_one(const std::string& what, const Printed& host, const Printed& image, bool check_status, double bound,
                 bool loud, Outcome& o) {
    ++o.compared;
    const bool same = std::memcmp(host.bits, image.bits, sizeof host.bits) == 0;
    o.identical += same ? 1 : 0;
    const double a = same ? 0.0 : angle_arcsec(host, image);
    o.worst = a > o.worst ? a : o.worst;
    std::string why;
    if (check_status && host.status != image.status) {
        why = "status " + std::to_string(image.status) + ", host " + std::to_string(host.status);
    } else if (bound == 0.0 && !same) {
        why = "q " + hex(image.bits[0]) + " " + hex(image.bits[1]) + " " + hex(image.bits[2]) + " " +
              hex(image.bits[3]) + ", host " + hex(host.bits[0]) + " " + hex(host.bits[1]) + " " + hex(host.bits[2]) +
              " " + hex(host.bits[3]) + " (bit for bit expected)";
    } else if (bound > 0.0 && !(a <= bound)) {
        why = "q " + std::to_string(a) + " arcsec from the host's (bound " + std::to_string(bound) + ")";
    }
    if (!why.empty()) {
        ++o.differences;
        if (loud) {
            std::cout << "  " << what << ": " << why << "\n";
        }
    }
}

// The largest difference two models' angles make over the loop's temperatures
// (each second of the profile, per head and axis), arcsec.
double model_difference(const Report::Model& a, const Report::Model& b) {
    using ascorr::app::chu_celsius;
    using ascorr::app::boom::profile_celsius;
    double worst = 0.0;
    for (std::uint32_t sec = 0; sec < ascorr::app::boom::kProfileSeconds; ++sec) {
        for (std::uint8_t h = 0; h < ascorr::kMaxHeads; ++h) {
            const double t1 = chu_celsius(h, sec);
            const double x[4] = {1.0, t1, profile_celsius(0U, sec) - t1, profile_celsius(3U, sec) - t1};
            for (std::size_t ax = 0; ax < ascorr::kModelAxes; ++ax) {
                double d = 0.0;
                for (std::size_t t = 0; t < ascorr::kLinearModelTerms; ++t) {
                    double ca = 0.0;
                    double cb = 0.0;
                    std::memcpy(&ca, &a.bits[h][ax][t], sizeof ca);
                    std::memcpy(&cb, &b.bits[h][ax][t], sizeof cb);
                    d += (ca - cb) * x[t];
                }
                worst = std::fabs(d) > worst || std::isnan(d) ? std::fabs(d) : worst;
            }
        }
    }
    return worst;
}

// The model histories: the same versions from the same cycles; bit for bit
// (CRC-32C and every coefficient) for BOUND 0, else the models' angles within
// BOUND of each other at every temperature of the loop (model_difference).
template <typename Differ>
void compare_models(const Report& host, const Report& image, double bound, Differ&& differ) {
    if (image.models.size() != host.models.size()) {
        differ(std::to_string(image.models.size()) + " models in the image's history, host " +
               std::to_string(host.models.size()));
    }
    for (std::size_t i = 0; i < host.models.size() && i < image.models.size(); ++i) {
        const Report::Model& e = host.models[i];
        const Report::Model& g = image.models[i];
        const std::string what = "model history entry " + std::to_string(i) + " (host: version " +
                                 std::to_string(e.version) + " from cycle " + std::to_string(e.cycle) + ")";
        if (g.version != e.version || g.cycle != e.cycle) {
            differ(what + ": the image's is version " + std::to_string(g.version) + " from cycle " +
                   std::to_string(g.cycle));
            continue;
        }
        bool rows = true;
        for (std::size_t h = 0; h < ascorr::kMaxHeads; ++h) {
            for (std::size_t a = 0; a < ascorr::kModelAxes; ++a) {
                rows = rows && g.row_seen[h][a];
            }
        }
        if (!rows) {
            differ(what + ": coefficient rows missing in the image's report");
            continue;
        }
        if (bound == 0.0) {
            if (g.crc != e.crc || std::memcmp(g.bits, e.bits, sizeof e.bits) != 0) {
                differ(what + ": crc32c " + hex(g.crc) + ", host " + hex(e.crc) + " (bit for bit expected)");
            }
        } else if (const double d = model_difference(e, g); !(d <= bound)) {
            differ(what + ": angles up to " + std::to_string(d) + " arcsec from the host's (bound " +
                   std::to_string(bound) + ")");
        }
    }
}

Outcome compare(const Report& host, const Report& image, double bound, bool loud) {
    Outcome o;
    auto differ = [&](const std::string& msg) {
        ++o.differences;
        if (loud) {
            std::cout << "  " << msg << "\n";
        }
    };
    for (unsigned h = 0; h < kRecords; ++h) {
        const std::string head = h == CorrectionLog::kCombined ? std::string("combined") : "head " + std::to_string(h);
        if (!image.head_seen[h]) {
            differ(head + ": no \"head\" line in the image's report");
            continue;
        }
        if (image.applied[h] != host.applied[h] || image.status_seen[h] != host.status_seen[h]) {
            differ(head + ": applied " + std::to_string(image.applied[h]) + " status seen " +
                   std::to_string(image.status_seen[h]) + ", host " + std::to_string(host.applied[h]) + " / " +
                   std::to_string(host.status_seen[h]));
        }
        compare_one(head + ", last solution (cycle " + std::to_string(host.cycles - 1U) + ")", host.last[h],
                    image.last[h], false, bound, loud, o);
        if (!image.crc_seen[h]) {
            differ(head + ": no \"solutions\" line in the image's report");
        } else if (image.crc_cycles[h] != host.crc_cycles[h] || (bound == 0.0 && image.crc[h] != host.crc[h])) {
            differ(head + ": CRC-32C of " + std::to_string(image.crc_cycles[h]) + " cycles " + hex(image.crc[h]) +
                   ", host " + std::to_string(host.crc_cycles[h]) + " cycles " + hex(host.crc[h]));
        }
    }
    if (image.samples.size() != host.samples.size()) {
        differ(std::to_string(image.samples.size()) + " samples, host " + std::to_string(host.samples.size()));
    }
    for (std::size_t i = 0; i < host.samples.size() && i < image.samples.size(); ++i) {
        const Report::Sample& e = host.samples[i];
        const Report::Sample& g = image.samples[i];
        const std::string what = "sample cycle " + std::to_string(e.cycle) + " head " + std::to_string(e.head);
        if (g.cycle != e.cycle || g.head != e.head) {
            differ(what + ": the image's line " + std::to_string(i + 1U) + " is cycle " + std::to_string(g.cycle) +
                   " head " + std::to_string(g.head));
            continue;
        }
        compare_one(what, e.s, g.s, true, bound, loud, o);
    }
    compare_models(host, image, bound, differ);
    return o;
}

// The smallest change the comparison must see: the first sample's w off by
// one bit (bit for bit), or the first sample rotated by twice the bound about
// its x axis (q ⊗ (cos θ/2, sin θ/2, 0, 0), θ = 2·bound).
Report mutated(Report r, double bound) {
    if (r.samples.empty()) {
        return r;
    }
    r.models.clear();  // compared alone: mutated_model()
    Printed& p = r.samples.front().s;
    if (bound == 0.0) {
        p.bits[0] ^= 1U;
        return r;
    }
    const double half = bound / kRadToArcsec;  // θ/2
    const double c = std::cos(half);
    const double sn = std::sin(half);
    double q[4];
    for (int i = 0; i < 4; ++i) {
        q[i] = value(p.bits[i]);
    }
    const double m[4] = {q[0] * c - q[1] * sn, q[1] * c + q[0] * sn, q[2] * c + q[3] * sn, q[3] * c - q[2] * sn};
    for (int i = 0; i < 4; ++i) {
        if constexpr (std::is_same_v<Scalar, float>) {
            p.bits[i] = ascorr::app::bits_of(static_cast<float>(m[i]));
        } else {
            p.bits[i] = static_cast<std::uint32_t>(static_cast<std::int32_t>(std::lround(m[i] * 1073741824.0)));
        }
    }
    return r;
}

// The last model of the history, its c0 of head A's α off by one bit (bit for
// bit) or by twice the bound (arcsec); the solutions left out (compared alone:
// mutated()).
Report mutated_model(Report r, double bound) {
    r.samples.clear();
    if (r.models.empty()) {
        return r;
    }
    std::uint64_t& b = r.models.back().bits[0][0][0];
    if (bound == 0.0) {
        b ^= 1U;
        return r;
    }
    double c = 0.0;
    std::memcpy(&c, &b, sizeof c);
    c += 2.0 * bound;
    std::memcpy(&b, &c, sizeof c);
    return r;
}

ascorr::app::FlightCycle& run(std::uint32_t cycles) {
    static ascorr::app::FlightCycle flight;  // static, as on the DPU
    ascorr::app::NoMeter meter;
    for (std::uint32_t cycle = 0U; cycle < cycles; ++cycle) {
        flight.run(cycle, meter, true);
        flight.learn_in_idle(meter);  // all at once: the DPU's spread gives the same bits (SunLearner::settle)
    }
    return flight;
}

Report::Sun sun_of(const ascorr::calib::SunLearnReport& r) {
    return {true,
            static_cast<unsigned>(r.cycles),
            r.orbits,
            static_cast<unsigned>(r.thinned),
            r.candidate.orbits,
            static_cast<unsigned>(r.candidate.rank),
            r.taken ? 1U : 0U,
            ascorr::calib::sun_fit_crc(r.candidate)};
}

// The Sun learner's state, the image's against the host's: the counts and
// whether the term is taken; bit for bit (bits), the candidate's rank and
// CRC too (an image whose float rounds otherwise could see an eigenvalue at
// the rank's cut on the other side). Each difference named; their number.
int sun_differences(const Report::Sun& host, const Report::Sun& image, bool bits, bool print) {
    if (!image.seen) {
        if (print) {
            std::cout << "  the image printed no \"sun learner:\" line\n";
        }
        return 1;
    }
    const std::pair<const char*, std::pair<unsigned, unsigned>> fields[] = {
        {"cycles", {host.cycles, image.cycles}},
        {"orbits", {host.orbits, image.orbits}},
        {"thinned", {host.thinned, image.thinned}},
        {"candidate orbits", {host.candidate_orbits, image.candidate_orbits}},
        {"rank", {bits ? host.rank : 0U, bits ? image.rank : 0U}},
        {"taken", {host.taken, image.taken}},
        {"crc32c", {bits ? host.crc : 0U, bits ? image.crc : 0U}}};
    int n = 0;
    for (const auto& [name, v] : fields) {
        if (v.first != v.second) {
            ++n;
            if (print) {
                std::cout << "  sun learner " << name << ": image " << v.second << ", host " << v.first << "\n";
            }
        }
    }
    return n;
}

// The image's stack: measured, at least kStackFloor (less is no real
// measure: the loop's frames, with the Sun learner's solve's, reach beyond
// it at any optimisation), and within three quarters of its size (the run
// takes not every path: the Sun term's stage, a different epoch's branches
// need room the painting never saw). An empty string, or what is wrong.
constexpr unsigned kStackFloor = 1024U;
std::string stack_problem(const Report::Stack& st) {
    if (!st.seen) {
        return "the image printed no \"stack:\" line";
    }
    if (st.used < kStackFloor) {
        return "the image's stack high-water mark " + std::to_string(st.used) + " B is below " +
               std::to_string(kStackFloor) + " B: its painting or scan is broken";
    }
    if (4U * st.used > 3U * st.size) {
        return "the image's stack reached " + std::to_string(st.used) + " bytes, beyond three quarters of its " +
               std::to_string(st.size);
    }
    return {};
}

bool parse_count(const char* s, unsigned long max, unsigned long& out) {
    char* end = nullptr;
    out = std::strtoul(s, &end, 10);
    return end != s && *end == '\0' && out >= 1UL && out <= max;
}

int usage(const char* argv0) {
    std::cerr << "usage: " << argv0 << " check REPORT BOUND_ARCSEC   (0: bit for bit)\n"
              << "       " << argv0 << " print CYCLES               (1 to 100000)\n";
    return 2;
}

}  // namespace

int main(int argc, char** argv) {
    if (argc == 3 && std::strcmp(argv[1], "print") == 0) {
        unsigned long cycles = 0UL;
        if (!parse_count(argv[2], 100000UL, cycles)) {
            return usage(argv[0]);
        }
        const ascorr::app::FlightCycle& flight = run(static_cast<std::uint32_t>(cycles));
        flight.record().print_heads();
        flight.record().print_solutions();
        flight.history().print();
        ascorr::app::print_sun_learner_state(flight.sun_learner().report());
        const ascorr::calib::EstimatorReport r = flight.estimator().report();
        std::cout << "self-calibration: orbits used " << r.orbits_used << " short " << r.orbits_short << " held "
                  << r.orbits_held << " late " << r.orbits_late << ", last refusal "
                  << ascorr::calib::refusal_name(r.last_refusal) << ", condition " << r.condition << ", residual RMS "
                  << r.residual_rms_arcsec << " arcsec, active version " << r.active_version << "\n";
        return 0;
    }
    if (argc != 4 || std::strcmp(argv[1], "check") != 0) {
        return usage(argv[0]);
    }
    char* end = nullptr;
    const double bound = std::strtod(argv[3], &end);
    if (end == argv[3] || *end != '\0' || !(bound >= 0.0 && bound < 3600.0)) {
        std::cerr << argv[0] << ": BOUND_ARCSEC '" << argv[3] << "' is not in [0, 3600)\n";
        return 2;
    }
    Report image;
    if (!parse_report(argv[2], image)) {
        return 1;
    }
    if (image.cycles > 100000U) {
        std::cerr << argv[2] << ": " << image.cycles << " cycles: more than this check runs (100000)\n";
        return 1;
    }
    const ascorr::app::FlightCycle& flight = run(image.cycles);
    Report host = from_record(flight.record(), image.cycles);
    add_history(flight.history(), host);
    std::cout << "flight loop vs the host core (" << (bound == 0.0 ? "bit for bit" : "within the bound") << "), "
              << image.cycles << " cycles:\n";
    const Outcome o = compare(host, image, bound, true);
    std::cout << "  " << o.compared << " quaternions compared (" << host.samples.size()
              << " samples and each head's last), " << o.identical << " bit for bit, worst " << o.worst << " arcsec";
    if (bound > 0.0) {
        std::cout << " (bound " << bound << ")";
    }
    std::cout << "; CRC-32C over every cycle " << (bound == 0.0 ? "compared" : "not compared (not bit for bit)")
              << "\n";
    if (o.differences != 0 || host.samples.empty()) {
        std::cout << "  " << o.differences
                  << " differences: the image's solutions or model history are not the host's\n";
        return 1;
    }
    if (host.models.size() < 2U || host.models.back().version < 1U) {
        std::cout << "  the estimator adopted no model in " << image.cycles << " cycles\n";
        return 1;
    }
    host.sun = sun_of(flight.sun_learner().report());
    if (sun_differences(host.sun, image.sun, bound == 0.0, true) != 0) {
        std::cout << "  the image's Sun learner is not the host's\n";
        return 1;
    }
    if (host.sun.orbits == 0U || host.sun.rank == 0U) {
        std::cout << "  the Sun learner solved nothing in " << image.cycles << " cycles\n";
        return 1;
    }
    if (const std::string p = stack_problem(image.stack); !p.empty()) {
        std::cout << "  " << p << "\n";
        return 1;
    }
    std::cout << "stack: " << image.stack.used << " of " << image.stack.size << " bytes at most\n";
    std::cout << "solutions match the host core's" << (bound == 0.0 ? " bit for bit" : " within the bound") << "\n";
    std::cout << "Sun learner (" << host.sun.cycles << " cycles, " << host.sun.orbits << " orbits, rank "
              << host.sun.rank << ") matches the host's" << (bound == 0.0 ? " bit for bit" : " in its counts") << "\n";
    std::cout << "model history (" << host.models.size() << " models, the last version " << host.models.back().version
              << " from cycle " << host.models.back().cycle << ") matches the host's"
              << (bound == 0.0 ? " bit for bit" : " within the bound") << "\n";
    Report image_solutions = image;
    image_solutions.models.clear();
    Report image_models = image;
    image_models.samples.clear();
    const Outcome m = compare(mutated(host, bound), image_solutions, bound, false);
    if (m.differences == 0) {
        std::cout << "  a mutated expectation (first sample perturbed) still matches: the comparison is vacuous\n";
        return 1;
    }
    const Outcome mm = compare(mutated_model(host, bound), image_models, bound, false);
    if (mm.differences == 0) {
        std::cout << "  a mutated expectation (last model perturbed) still matches: the comparison is vacuous\n";
        return 1;
    }
    Report::Sun mutated_sun = host.sun;
    mutated_sun.crc ^= 1U;  // bit for bit: the CRC's last bit
    mutated_sun.orbits += bound == 0.0 ? 0U : 1U;
    if (sun_differences(mutated_sun, image.sun, bound == 0.0, false) == 0) {
        std::cout << "  a mutated expectation (the Sun learner's) still matches: the comparison is vacuous\n";
        return 1;
    }
    Report::Stack deeper = image.stack;
    deeper.used = deeper.size * 3U / 4U + 4U;
    Report::Stack shallow = image.stack;
    shallow.used = kStackFloor - 4U;
    if (stack_problem(deeper).empty() || stack_problem(shallow).empty()) {
        std::cout << "  a stack mark one word beyond its bounds passes the check: the check is vacuous\n";
        return 1;
    }
    std::cout << "mutated expectation refused\n";
    return 0;
}
