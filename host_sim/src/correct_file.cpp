#include "ascorr_host/correct_file.hpp"

#include <charconv>
#include <cmath>
#include <cstdio>
#include <optional>
#include <ostream>
#include <sstream>
#include <stdexcept>

#include "ascorr/correct.hpp"
#include "ascorr_host/atomic_file.hpp"
#include "ascorr_host/csv.hpp"
#include "ascorr_host/diagnostics.hpp"
#include "ascorr_host/input_error.hpp"
#include "ascorr_host/model_csv.hpp"
#include "ascorr_host/solution_input.hpp"
#include "ascorr_host/solutions_csv.hpp"

namespace ascorr::host {

namespace {

constexpr std::size_t kFlushBytes = 1U << 20;

std::string where(const std::string& file, const SolutionRecord& rec) {
    return file + ":" + std::to_string(rec.line) + ": ";
}

// Explains, once per affected row, the status bits that mean "bad input".
template <typename T>
void explain(const SolutionRecord& rec, const SolutionInput<T>& in, StatusBits st, const std::string& file,
             Diagnostics& diag) {
    if ((st & status::kRejected) != 0U) {
        std::string why;
        switch (check_solution(in)) {
            case Rejection::kHeadOutOfRange:
                why = "chu '" + std::string(rec.chu) + "' is not a camera head (A, B, C or D)";
                break;
            case Rejection::kQuaternionNotFinite:
                why = "quaternion is not finite";
                break;
            case Rejection::kQuaternionNotUnit: {
                const auto& q = rec.q_chu_icrf;
                char buf[96];
                std::snprintf(buf, sizeof buf, "quaternion is not unit (|q|^2 = %.9g, tolerance %.1g)",
                              q.w * q.w + q.x * q.x + q.y * q.y + q.z * q.z,
                              static_cast<double>(ScalarTraits<T>::unit_norm_tolerance));
                why = buf;
                break;
            }
            case Rejection::kNone:
                break;
        }
        diag.report("rejected", where(file, rec) + why + ": row kept, quaternion unchanged (status 16)");
        return;
    }
    if ((st & status::kVelocityInvalid) != 0U) {
        if (rec.velocity_components != 3) {
            diag.report("velocity incomplete", where(file, rec) + "only " + std::to_string(rec.velocity_components) +
                                                   " of vx,vy,vz given: aberration skipped");
        } else {
            const auto b = in.velocity.beta_icrf;
            const double speed = std::sqrt(ScalarTraits<T>::to_double(squared_norm(b))) * kSpeedOfLightKmS;
            char buf[128];
            std::snprintf(buf, sizeof buf, "observer speed %.6g km/s is not below %.0f km/s: aberration skipped", speed,
                          kMaxObserverSpeedKmS);
            diag.report("velocity invalid", where(file, rec) + buf);
        }
    }
    if ((st & status::kTemperatureInvalid) != 0U) {
        char buf[160];
        std::snprintf(buf, sizeof buf, "temperature outside +-%.0f C (t_chu=%g, t_029=%g, t_032=%g): thermal skipped",
                      kMaxAbsTemperatureC, rec.temperature[0], rec.temperature[1], rec.temperature[2]);
        diag.report("temperature invalid", where(file, rec) + buf);
    }
    if ((st & status::kThermalOutOfRange) != 0U) {
        diag.report("thermal out of range",
                    where(file, rec) + "model angle beyond 1 degree for these temperatures: thermal skipped");
    }
    if ((st & status::kNoModelForHead) != 0U) {
        diag.report("no model for head",
                    where(file, rec) + "the model has no coefficients for chu '" + std::string(rec.chu) + "': thermal skipped");
    }
}

class RowWriter {
public:
    RowWriter(const SolutionsReader& reader, AtomicFile& out) : reader_(reader), out_(out) {
        const auto& c = reader.columns();
        q_cols_ = {c.qw, c.qx, c.qy, c.qz};
        status_col_ = reader.header().index("status");
        const auto& names = reader.header().names();
        for (std::size_t i = 0; i < names.size(); ++i) {
            buf_ += (i == 0 ? "" : ",");
            buf_ += names[i];
        }
        if (status_col_ < 0) {
            buf_ += ",status";
        }
        buf_ += '\n';
    }

    void row(const std::optional<Quaternion<double>>& q, StatusBits st) {
        const auto& fields = reader_.fields();
        char num[64];
        for (std::size_t i = 0; i < fields.size(); ++i) {
            if (i != 0) {
                buf_ += ',';
            }
            const int col = static_cast<int>(i);
            if (col == status_col_) {
                append_status(st);
            } else if (q && (col == q_cols_[0] || col == q_cols_[1] || col == q_cols_[2] || col == q_cols_[3])) {
                const double v = col == q_cols_[0] ? q->w : col == q_cols_[1] ? q->x : col == q_cols_[2] ? q->y : q->z;
                buf_.append(num, format_fixed(num, num + sizeof num, v, 15));
            } else {
                buf_.append(fields[i]);
            }
        }
        if (status_col_ < 0) {
            buf_ += ',';
            append_status(st);
        }
        buf_ += '\n';
        if (buf_.size() >= kFlushBytes) {
            flush();
        }
    }

    void flush() {
        out_.write(buf_);
        buf_.clear();
    }

private:
    void append_status(StatusBits st) {
        char num[8];
        const auto r = std::to_chars(num, num + sizeof num, static_cast<unsigned>(st));
        buf_.append(num, r.ptr);
    }

    const SolutionsReader& reader_;
    AtomicFile& out_;
    std::array<int, 4> q_cols_{};
    int status_col_ = -1;
    std::string buf_;
};

template <typename T>
CorrectSummary run(const CorrectOptions& opt, std::ostream& log) {
    const std::string text = read_text_file(opt.in);
    SolutionsReader reader(opt.in, text);

    std::optional<ThermalModel<T>> model;
    if (opt.thermal && !opt.model.empty()) {
        model = to_core<T>(read_model_file(opt.model));
    }
    const CorrectionConfig<T> cfg{opt.aberration, model ? &*model : nullptr};

    Diagnostics diag(log);
    EarthVelocity earth;
    AtomicFile out(opt.out);
    RowWriter writer(reader, out);
    CorrectSummary sum;
    SolutionRecord rec;
    for (;;) {
        try {
            if (!reader.next(rec)) {
                break;
            }
        } catch (const InputError& e) {
            if (!opt.skip_bad) {
                throw;
            }
            ++sum.malformed;
            diag.report("malformed", std::string(e.what()) + " (row skipped: --skip-bad)");
            continue;
        }
        const SolutionInput<T> in = to_core_input<T>(rec, opt.aberration ? &earth : nullptr);
        const CorrectedSolution<T> c = correct_solution(in, cfg);
        StatusBits st = c.status;
        if (opt.aberration && rec.velocity_components != 0 && rec.velocity_components != 3) {
            st |= status::kVelocityInvalid;  // partial velocity: the core saw "not available"
        }
        explain(rec, in, st, opt.in, diag);
        if ((st & status::kRejected) != 0U) {
            writer.row(std::nullopt, st);  // the input text, unchanged
        } else {
            const auto d = [](const T& x) { return ScalarTraits<T>::to_double(x); };
            writer.row(Quaternion<double>{d(c.q_chu_icrf.w), d(c.q_chu_icrf.x), d(c.q_chu_icrf.y), d(c.q_chu_icrf.z)}, st);
        }
        ++sum.rows;
        for (std::size_t b = 0; b < sum.status_bit.size(); ++b) {
            sum.status_bit[b] += (st >> b) & 1U;
        }
    }
    if (reader.empty_lines() != 0) {
        log << opt.in << ": " << reader.empty_lines() << " empty line(s) ignored\n";
    }
    diag.summarize();
    writer.flush();
    out.commit();
    return sum;
}

}  // namespace

CorrectSummary correct_file(const CorrectOptions& opt, std::ostream& log) {
    switch (opt.scalar) {
        case Scalar::kDouble:
            return run<double>(opt, log);
        case Scalar::kFloat:
            return run<float>(opt, log);
        case Scalar::kFixed:
            break;
    }
    throw std::runtime_error("--scalar fixed: the fixed-point core is not part of this build yet");
}

std::string describe(const CorrectSummary& s) {
    std::ostringstream o;
    o << s.rows << " rows written";
    const char* names[] = {"aberration applied", "thermal applied", "no velocity", "temperatures missing",
                           "rejected",           "velocity invalid", "temperature invalid", "thermal out of range",
                           "no model for head"};
    for (std::size_t b = 0; b < 9; ++b) {
        if (s.status_bit[b] != 0) {
            o << ", " << s.status_bit[b] << " " << names[b];
        }
    }
    if (s.malformed != 0) {
        o << ", " << s.malformed << " malformed rows skipped";
    }
    return o.str();
}

}  // namespace ascorr::host
