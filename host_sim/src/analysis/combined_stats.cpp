#include "ascorr_host/analysis/combined_stats.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <optional>
#include <sstream>

#include "ascorr/core/constants.hpp"
#include "ascorr/core/heads.hpp"
#include "ascorr/core/rotation_vector.hpp"
#include "ascorr_host/analysis/iba.hpp"
#include "ascorr_host/formats/combined_csv.hpp"
#include "ascorr_text/c_format.hpp"
#include "ascorr_text/input_error.hpp"

namespace ascorr::host {

namespace {

using Vec = std::array<double, 3>;

struct Sums {
    std::size_t n = 0;
    Vec sum{};
    Vec sum_sq{};
    void add(const Vec& v) {
        ++n;
        for (std::size_t a = 0; a < 3; ++a) {
            sum[a] += v[a];
            sum_sq[a] += v[a] * v[a];
        }
    }
    Vec mean() const {
        Vec m{};
        for (std::size_t a = 0; a < 3; ++a) {
            m[a] = n == 0 ? std::nan("") : sum[a] / static_cast<double>(n);
        }
        return m;
    }
    Vec rms() const {
        Vec r{};
        for (std::size_t a = 0; a < 3; ++a) {
            r[a] = n == 0 ? std::nan("") : std::sqrt(sum_sq[a] / static_cast<double>(n));
        }
        return r;
    }
};

struct SetAccumulator {
    std::size_t epochs = 0;
    Sums error;
    Sums sigma;
    std::map<long long, Sums> daily;  // day -> errors
};

// The truth rows, in time order, read along with the combined file's.
class TruthCursor {
public:
    explicit TruthCursor(const std::string& path) : reader_(path) { advance(); }
    // The truth at key, if it has a row there; keys asked in increasing order.
    const AttitudeRow* at(std::int64_t key) {
        while (more_ && key_ < key) {
            advance();
        }
        return more_ && key_ == key ? &row_ : nullptr;
    }
    // The rows after the last asked for are checked too (a truth in reverse
    // order is refused, not taken as one without rows).
    void finish() {
        while (more_) {
            advance();
        }
    }

private:
    void advance() {
        more_ = reader_.next(row_);
        key_ = more_ ? epoch_key(row_.t) : key_;
    }
    TruthReader reader_;
    AttitudeRow row_;
    std::int64_t key_ = 0;
    bool more_ = false;
};

// Most heads first, then heads.hpp's order (the mask's lowest bits first); none last.
bool set_order(HeadMask a, HeadMask b) {
    if ((a == 0) != (b == 0)) {
        return b == 0;
    }
    if (head_count(a) != head_count(b)) {
        return head_count(a) > head_count(b);
    }
    for (std::uint8_t h = 0; h < kMaxHeads; ++h) {
        const bool ha = has_head(a, h);
        const bool hb = has_head(b, h);
        if (ha != hb) {
            return ha;
        }
    }
    return false;
}

void steps_against_full(std::map<HeadMask, SetAccumulator>& acc, CombinedStats& s) {
    const auto full = acc.find(s.full);
    for (HeadSetReport& r : s.sets) {
        if (full == acc.end() || r.heads == s.full || r.heads == 0) {
            continue;
        }
        Sums diff;
        for (const auto& [day, sums] : acc[r.heads].daily) {
            const auto f = full->second.daily.find(day);
            if (f == full->second.daily.end()) {
                continue;
            }
            const Vec ms = sums.mean();
            const Vec mf = f->second.mean();
            diff.add({ms[0] - mf[0], ms[1] - mf[1], ms[2] - mf[2]});
        }
        r.step_days = diff.n;
        r.step = diff.rms();
    }
}

}  // namespace

std::string head_set_name(HeadMask heads) {
    return heads == 0 ? std::string("-") : head_letters(heads);
}

CombinedStats combined_stats(const CombinedStatsOptions& opt) {
    AttitudeReader reader(opt.combined);
    if (!reader.combined()) {
        throw text::InputError(opt.combined, 1, 1,
                               "expected a combined file (t,qw,qx,qy,qz,heads,sigma_x,sigma_y,sigma_z,status)");
    }
    std::optional<TruthCursor> truth;
    if (!opt.truth.empty()) {
        truth.emplace(opt.truth);
    }
    CombinedStats s;
    s.truth = truth.has_value();
    std::map<HeadMask, SetAccumulator> acc;
    AttitudeRow row;
    double t0 = 0.0;
    std::int64_t last_key = 0;
    while (reader.next(row)) {
        const std::int64_t key = epoch_key(row.t);
        if (s.epochs != 0 && key <= last_key) {
            throw text::InputError(
                opt.combined, row.line, 1,
                "a combined file has one row per epoch, in time order: this row is not after the last");
        }
        t0 = s.epochs == 0 ? row.t : t0;
        last_key = key;
        ++s.epochs;
        for (std::size_t b = 0; b < s.status_bit.size(); ++b) {
            s.status_bit[b] += (row.status >> b) & 1U;
        }
        SetAccumulator& a = acc[row.heads];
        ++a.epochs;
        if (!truth || !row.has_q) {
            continue;
        }
        const AttitudeRow* tr = truth->at(key);
        if (tr == nullptr) {
            ++s.epochs_without_truth;
            continue;
        }
        const Vector3<double> v = rotation_vector_arcsec(row.q_crf_icrf, tr->q_crf_icrf);
        const Vec e{v.x, v.y, v.z};
        a.error.add(e);
        a.sigma.add(row.sigma_arcsec);
        a.daily[static_cast<long long>(std::floor((row.t - t0) / kSecondsPerDay))].add(e);
    }
    std::size_t full_epochs = 0;
    for (const auto& [heads, a] : acc) {
        HeadSetReport r;
        r.heads = heads;
        r.epochs = a.epochs;
        r.with_truth = a.error.n;
        r.error_rms = a.error.rms();
        r.error_mean = a.error.mean();
        r.sigma_rms = a.sigma.rms();
        r.step = {std::nan(""), std::nan(""), std::nan("")};
        s.sets.push_back(r);
        const bool fuller = heads != 0 && (head_count(heads) > head_count(s.full) ||
                                           (head_count(heads) == head_count(s.full) && a.epochs > full_epochs));
        if (fuller) {
            s.full = heads;
            full_epochs = a.epochs;
        }
    }
    std::sort(s.sets.begin(), s.sets.end(),
              [](const HeadSetReport& a, const HeadSetReport& b) { return set_order(a.heads, b.heads); });
    if (truth) {
        truth->finish();
        steps_against_full(acc, s);
    }
    return s;
}

namespace {

std::string triple(const Vec& v, const char* format) {
    std::string out;
    char buf[48];
    for (std::size_t a = 0; a < 3; ++a) {
        if (std::isnan(v[a])) {
            out += a == 0 ? "       -" : "        -";
            continue;
        }
        text::c_snprintf(buf, sizeof buf, format, a == 0 ? "" : " ", v[a]);
        out += buf;
    }
    return out;
}

std::string json_triple(const Vec& v) {
    if (std::isnan(v[0]) || std::isnan(v[1]) || std::isnan(v[2])) {
        return "null";
    }
    char buf[96];
    text::c_snprintf(buf, sizeof buf, "[%.6f, %.6f, %.6f]", v[0], v[1], v[2]);
    return buf;
}

}  // namespace

std::string combined_stats_table(const CombinedStats& s) {
    std::ostringstream o;
    o << s.epochs << " epochs: " << s.status_bit[0] << " two or more heads (1), " << s.status_bit[1]
      << " one head (2), " << s.status_bit[2] << " a head left out (4), " << s.status_bit[3] << " no usable head (8)\n";
    if (!s.truth) {
        o << "heads  epochs\n";
        for (const HeadSetReport& r : s.sets) {
            char line[64];
            text::c_snprintf(line, sizeof line, "%-5s %7zu\n", head_set_name(r.heads).c_str(), r.epochs);
            o << line;
        }
        return o.str();
    }
    o << "error against the truth per CRF axis (x y z, arcsec); step: RMS over days of the daily mean error "
         "minus the full set's ("
      << head_set_name(s.full) << ")\n";
    o << "heads  epochs |     RMS error (x y z)     |    mean error (x y z)     |     formal sigma (x y z)  |       "
         "step (x y z)        days\n";
    for (const HeadSetReport& r : s.sets) {
        char head[32];
        text::c_snprintf(head, sizeof head, "%-5s %7zu", head_set_name(r.heads).c_str(), r.epochs);
        o << head << " | " << triple(r.error_rms, "%s%8.3f") << " | " << triple(r.error_mean, "%s%8.3f") << " | "
          << triple(r.sigma_rms, "%s%8.3f") << " | " << triple(r.step, "%s%8.3f");
        char days[24];
        text::c_snprintf(days, sizeof days, " %5zu\n", r.step_days);
        o << days;
    }
    if (s.epochs_without_truth != 0) {
        o << s.epochs_without_truth << " epochs without a truth row (not in the errors)\n";
    }
    return o.str();
}

std::string combined_stats_json(const CombinedStats& s) {
    std::ostringstream o;
    o << "{\"epochs\": " << s.epochs << ", \"status\": {\"1\": " << s.status_bit[0] << ", \"2\": " << s.status_bit[1]
      << ", \"4\": " << s.status_bit[2] << ", \"8\": " << s.status_bit[3] << "}, \"full\": \"" << head_set_name(s.full)
      << "\", \"head_sets\": {";
    for (std::size_t i = 0; i < s.sets.size(); ++i) {
        const HeadSetReport& r = s.sets[i];
        o << (i ? ", " : "") << '"' << head_set_name(r.heads) << "\": {\"epochs\": " << r.epochs
          << ", \"with_truth\": " << r.with_truth << ", \"error_rms\": " << json_triple(r.error_rms)
          << ", \"error_mean\": " << json_triple(r.error_mean) << ", \"sigma_rms\": " << json_triple(r.sigma_rms)
          << ", \"step\": " << json_triple(r.step) << ", \"step_days\": " << r.step_days << '}';
    }
    o << "}}\n";
    return o.str();
}

}  // namespace ascorr::host
