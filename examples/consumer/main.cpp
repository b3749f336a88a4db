// examples/consumer/main.cpp: a DPU-style program built against the installed
// ascorr package (ascorr::core, ascorr::hal). It corrects the data contract's
// worked example through the thermal stage in double, float and Q30 and
// compares each result with the independently computed expected output.
//
//   ascorr_consumer solutions.csv model.csv expected_thermal_only.csv
//
// The CSV reading here is deliberately plain (the example files are
// well-formed); a firmware gets its inputs from its own bus. Prints the largest
// angle to the expected attitude per scalar and exits 0 when each is within
// its bound: 1e-6" (double), 0.05" (float), 0.01" (Q30); 1 otherwise or on a
// read error.
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>

#include "ascorr/ascorr.hpp"
#include "ascorr/core/model_coefficients.hpp"
#include "ascorr_hal/thermistor.hpp"  // installed with the package (unused beyond this check)
#include "ascorr_link/frame.hpp"

namespace {

constexpr int kMaxRows = 64;

struct Row {
    char chu;
    double q[4];
    double temp[3];
};

struct ModelRow {
    char chu;
    char axis;  // 'a', 'b', 'g'
    double c[4];
};

// Reads `n` comma-separated doubles after the first `skip` fields of a line.
bool fields(const char* line, int skip, double* out, int n) {
    const char* p = line;
    for (int i = 0; i < skip; ++i) {
        p = std::strchr(p, ',');
        if (p == nullptr) {
            return false;
        }
        ++p;
    }
    for (int i = 0; i < n; ++i) {
        char* end = nullptr;
        out[i] = std::strtod(p, &end);
        if (end == p || (*end != ',' && *end != '\n' && *end != '\0' && *end != '\r')) {
            return false;
        }
        p = *end == ',' ? end + 1 : end;
    }
    return true;
}

// Calls take(line, row) for each line after the header, at most kMaxRows;
// the number of rows, or -1 when the file cannot be read or take() refuses a line.
template <typename R, typename F>
int read_lines(const char* path, R* rows, F take) {
    std::FILE* f = std::fopen(path, "r");
    if (f == nullptr) {
        return -1;
    }
    char line[512];
    int n = 0;
    bool header = true;
    while (std::fgets(line, sizeof line, f) != nullptr && n < kMaxRows) {
        if (header) {
            header = false;
            continue;
        }
        if (!take(line, rows[n])) {
            std::fclose(f);
            return -1;
        }
        ++n;
    }
    std::fclose(f);
    return n;
}

// solutions / expected: t,chu,qw,qx,qy,qz,t_chu,t_029,t_032,...
int read_rows(const char* path, Row* rows) {
    return read_lines(path, rows, [](const char* line, Row& row) {
        const char* chu = std::strchr(line, ',');
        double v[7];
        if (chu == nullptr || !fields(line, 2, v, 7)) {
            return false;
        }
        row = {chu[1], {v[0], v[1], v[2], v[3]}, {v[4], v[5], v[6]}};
        return true;
    });
}

// model: chu,axis,c0,c1,c2,c3 (linear, as Table 2)
int read_model(const char* path, ModelRow* rows) {
    return read_lines(path, rows, [](const char* line, ModelRow& row) {
        double c[4];
        if (!fields(line, 2, c, 4)) {
            return false;
        }
        row = {line[0],
               std::strncmp(line + 2, "alpha", 5) == 0  ? 'a'
               : std::strncmp(line + 2, "beta", 4) == 0 ? 'b'
                                                        : 'g',
               {c[0], c[1], c[2], c[3]}};
        return true;
    });
}

// The rows in the core's layout (arcsec); the installed core converts them
// (ascorr/core/model_coefficients.hpp).
ascorr::ModelCoefficients coefficients_of(const ModelRow* rows, int n) {
    ascorr::ModelCoefficients m{};
    for (int i = 0; i < n; ++i) {
        const std::uint8_t h = ascorr::head_index(rows[i].chu);
        if (h >= ascorr::kMaxHeads) {
            continue;
        }
        m.present[h] = true;
        const int axis = rows[i].axis == 'a' ? 0 : rows[i].axis == 'b' ? 1 : 2;
        for (int c = 0; c < 4; ++c) {
            m.coefficient[h][axis][c] = rows[i].c[c];
        }
    }
    return m;
}

// Largest angle (arcsec) between the corrected and the expected attitudes.
template <typename T>
double max_error_arcsec(const Row* in, const Row* want, int n, const ModelRow* model, int nm) {
    using Tr = ascorr::ScalarTraits<T>;
    const ascorr::ThermalModel<T> m = ascorr::thermal_model<T>(coefficients_of(model, nm), ascorr::kArcsecToRad);
    const ascorr::CorrectionConfig<T> cfg{false, &m};
    double worst = 0.0;
    for (int i = 0; i < n; ++i) {
        ascorr::SolutionInput<T> s{};
        s.q_chu_icrf = {Tr::from_double(in[i].q[0]), Tr::from_double(in[i].q[1]), Tr::from_double(in[i].q[2]),
                        Tr::from_double(in[i].q[3])};
        s.head = ascorr::head_index(in[i].chu);
        s.temperatures = {
            {Tr::celsius(in[i].temp[0]), true}, {Tr::celsius(in[i].temp[1]), true}, {Tr::celsius(in[i].temp[2]), true}};
        s.velocity.valid = false;
        const ascorr::CorrectedSolution<T> out = ascorr::correct_solution(s, cfg);
        const double got[4] = {Tr::to_double(out.q_chu_icrf.w), Tr::to_double(out.q_chu_icrf.x),
                               Tr::to_double(out.q_chu_icrf.y), Tr::to_double(out.q_chu_icrf.z)};
        // The angle between two unit quaternions from their chord (exact for
        // small angles, where 2·acos(|q1·q2|) loses half the digits): q and −q
        // are one attitude, so take the nearer sign.
        double dot = 0.0;
        for (int c = 0; c < 4; ++c) {
            dot += got[c] * want[i].q[c];
        }
        const double sign = dot < 0.0 ? -1.0 : 1.0;
        double chord2 = 0.0;
        for (int c = 0; c < 4; ++c) {
            const double e = got[c] - sign * want[i].q[c];
            chord2 += e * e;
        }
        const double angle = 4.0 * std::asin(std::fmin(1.0, 0.5 * std::sqrt(chord2))) * ascorr::kRadToArcsec;
        if ((out.status & ascorr::status::kThermalApplied) == 0U) {
            std::printf("row %d: thermal stage not applied (status %u)\n", i + 1, static_cast<unsigned>(out.status));
            return HUGE_VAL;
        }
        worst = std::fmax(worst, angle);
    }
    return worst;
}

}  // namespace

int main(int argc, char** argv) {
    if (argc != 4) {
        std::fputs("usage: ascorr_consumer solutions.csv model.csv expected_thermal_only.csv\n", stderr);
        return 1;
    }
    static Row in[kMaxRows];
    static Row want[kMaxRows];
    static ModelRow model[kMaxRows];
    const int n = read_rows(argv[1], in);
    const int nw = read_rows(argv[3], want);
    const int nm = read_model(argv[2], model);
    if (n <= 0 || nw != n || nm <= 0) {
        std::fputs("ascorr_consumer: cannot read the example files\n", stderr);
        return 1;
    }
    const double e_double = max_error_arcsec<double>(in, want, n, model, nm);
    const double e_float = max_error_arcsec<float>(in, want, n, model, nm);
    const double e_q30 = max_error_arcsec<ascorr::Q30>(in, want, n, model, nm);
    std::printf(
        "ascorr package (link protocol %u): %d worked-example rows, thermal stage, max error vs expected: "
        "double %.3g\", float %.3g\", Q30 %.3g\"\n",
        static_cast<unsigned>(ascorr::link::kProtocolVersion), n, e_double, e_float, e_q30);
    return e_double <= 1e-6 && e_float <= 0.05 && e_q30 <= 0.01 ? 0 : 1;
}
