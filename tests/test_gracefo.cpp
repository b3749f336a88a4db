// tests/test_gracefo.cpp: `ascorr import gracefo` on the public GRACE-FO
// sample (tests/data/gracefo, issue 39): the records against this test's own
// reading of the files, the bench's attitude against JPL's, and bad records.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "ascorr/core/constants.hpp"
#include "ascorr_host/formats/combined_csv.hpp"
#include "ascorr_host/formats/solutions_csv.hpp"
#include "cli_run.hpp"
#include "test_support.hpp"

namespace ascorr {
namespace {

namespace fs = std::filesystem;
using test::run_in;

const fs::path kData = fs::path(ASCORR_TEST_DATA) / "gracefo";

std::string product(const std::string& name, char sat) {
    const std::string day = name == "QSA1B" ? "2018-05-22" : "2023-06-01";
    return (kData / (name + "_" + day + "_" + sat + "_04.txt")).string();
}

// The records after the header, each split at whitespace (this test's own reading).
std::vector<std::vector<std::string>> records(const std::string& path) {
    std::ifstream in(path);
    std::string line;
    bool header = true;
    std::vector<std::vector<std::string>> out;
    while (std::getline(in, line)) {
        if (header) {
            header = line.rfind("# End of YAML header", 0) != 0 && line.rfind("END OF HEADER", 0) != 0;
            continue;
        }
        std::istringstream s(line);
        std::vector<std::string> f;
        for (std::string w; s >> w;) {
            f.push_back(w);
        }
        if (!f.empty()) {
            out.push_back(f);
        }
    }
    return out;
}

// Offset (s) of a TIM1B or CLK1B table at x, linear between records, the end
// records' own offset just outside them.
double offset_at(const std::vector<std::pair<double, double>>& table, double x) {
    if (x <= table.front().first) {
        return table.front().second;
    }
    for (std::size_t i = 1; i < table.size(); ++i) {
        if (table[i].first >= x) {
            const double u = (x - table[i - 1].first) / (table[i].first - table[i - 1].first);
            return table[i - 1].second + u * (table[i].second - table[i - 1].second);
        }
    }
    return table.back().second;
}

std::string import_args(char sat, const std::string& extra = "") {
    return "import gracefo --sca1a " + product("SCA1A", sat) + " --qsa1b " + product("QSA1B", sat) + " --tim1b " +
           product("TIM1B", sat) + " --clk1b " + product("CLK1B", sat) + " --sca1b " + product("SCA1B", sat) +
           " --out sol.csv --mountings m.csv --reference ref.csv " + extra;
}

TEST(GracefoImport, SolutionsEqualAnIndependentReadingOfTheFiles) {
    for (const char sat : {'C', 'D'}) {
        const fs::path dir = test::scratch_dir(std::string("gracefo_reading_") + sat);
        ASSERT_EQ(run_in(import_args(sat), dir).exit_code, 0) << test::slurp(dir / "stderr.txt");
        std::vector<std::pair<double, double>> tim;
        for (const auto& r : records(product("TIM1B", sat))) {
            tim.emplace_back(std::stod(r[0]), std::stod(r[3]) - std::stod(r[0]) + 1e-9 * std::stod(r[4]));
        }
        std::vector<std::pair<double, double>> clk;
        for (const auto& r : records(product("CLK1B", sat))) {
            clk.emplace_back(std::stod(r[0]), std::stod(r[3]));
        }
        const auto sca = records(product("SCA1A", sat));
        std::string storage;
        const std::vector<host::SolutionRecord> got = test::read_records((dir / "sol.csv").string(), storage);
        ASSERT_EQ(got.size(), sca.size());
        ASSERT_EQ(got.size(), 100U);
        for (std::size_t i = 0; i < sca.size(); ++i) {
            const auto& r = sca[i];
            const double obc = std::stod(r[0]) + 1e-6 * std::stod(r[1]);
            const double rcv = obc + offset_at(tim, obc);
            const double t = rcv + offset_at(clk, rcv) + 51.184;
            EXPECT_NEAR(got[i].t, t, 1e-6) << sat << " record " << i;
            EXPECT_EQ(got[i].head, std::stoi(r[3]) - 1);
            // q_chu_icrf: the conjugate of SCA1A's (which takes the camera frame into inertial)
            EXPECT_NEAR(got[i].q_chu_icrf.w, std::stod(r[5]), 1e-15);
            EXPECT_NEAR(got[i].q_chu_icrf.x, -std::stod(r[6]), 1e-15);
            EXPECT_NEAR(got[i].q_chu_icrf.y, -std::stod(r[7]), 1e-15);
            EXPECT_NEAR(got[i].q_chu_icrf.z, -std::stod(r[8]), 1e-15);
            EXPECT_EQ(got[i].flags, 0);               // valid, aberration corrected on board, no false stars
            EXPECT_FALSE(got[i].confidence_present);  // sca_confid is no misfit in arcsec
            EXPECT_FALSE(got[i].temperature_present[0] || got[i].velocity_components > 0);
        }
        // The quality fields as they are, after the contract's columns.
        std::ifstream text(dir / "sol.csv");
        std::string line;
        std::getline(text, line);
        EXPECT_EQ(line, "t,chu,qw,qx,qy,qz,t_chu,t_029,t_032,vx,vy,vz,flags,confidence,sca_mode,qualflg,sca_confid");
        for (const auto& r : sca) {
            std::getline(text, line);
            const std::string want = "," + std::to_string(std::stoi(r[14], nullptr, 2)) + "," +
                                     std::to_string(std::stoi(r[15], nullptr, 2)) + "," + r[11];
            EXPECT_EQ(line.substr(line.size() - want.size()), want);
            // Temperatures and velocity empty, as the contract writes them (was: nan,nan,nan,,,).
            std::size_t start = 0;
            for (int comma = 0; comma < 6; ++comma) {
                start = line.find(',', start) + 1;
            }
            EXPECT_EQ(line.substr(start, 6), ",,,,,,") << line;
        }
        // the clock products matter: 16.7 ms of receiver clock offset on this day
        EXPECT_LT(got[0].t - (std::stod(sca[0][0]) + 1e-6 * std::stod(sca[0][1]) + 51.184), -0.016);
        const auto ref = records(product("SCA1B", sat));
        std::vector<host::AttitudeRow> rows;
        host::AttitudeReader reader((dir / "ref.csv").string());
        for (host::AttitudeRow row; reader.next(row);) {
            rows.push_back(row);
        }
        ASSERT_EQ(rows.size(), ref.size());
        for (std::size_t i = 0; i < ref.size(); ++i) {
            EXPECT_EQ(rows[i].t, std::stod(ref[i][0]) + 51.184);
            const double sign = std::stod(ref[i][3]) < 0.0 ? -1.0 : 1.0;  // written with qw >= 0
            EXPECT_NEAR(rows[i].q_crf_icrf.w, sign * std::stod(ref[i][3]), 1e-15);
            EXPECT_NEAR(rows[i].q_crf_icrf.x, -sign * std::stod(ref[i][4]), 1e-15);
        }
        const auto qsa = records(product("QSA1B", sat));
        const std::string m = test::slurp(dir / "m.csv");
        EXPECT_EQ(m.rfind("chu,qw,qx,qy,qz\n", 0), 0U) << m;
        EXPECT_NE(m.find("A," + qsa[0][3]), std::string::npos) << m;  // q_chu_crf as written in QSA1B
    }
}

// The error of q against ref as a rotation vector in CRF axes (Eigen), arcsec.
Eigen::Vector3d error_arcsec(const Quaternion<double>& q, const Quaternion<double>& ref) {
    const Eigen::AngleAxisd d(test::to_eigen(q) * test::to_eigen(ref).conjugate());
    const double angle = d.angle() > kPi ? d.angle() - 2.0 * kPi : d.angle();
    return d.axis() * angle * kRadToArcsec;
}

// Per CRF axis, the RMS about the mean of the interpolated attitude against
// SCA1B at SCA1B's own times; n: the times compared.
Eigen::Vector3d rms_against_jpl(const fs::path& dir, const std::string& combined, std::size_t& n) {
    EXPECT_EQ(run_in("interpolate --in " + combined + " --at ref.csv --out at.csv", dir).exit_code, 0);
    host::AttitudeReader ref((dir / "ref.csv").string());
    host::AttitudeReader at((dir / "at.csv").string());
    std::vector<Eigen::Vector3d> e;
    host::AttitudeRow r;
    host::AttitudeRow a;
    while (ref.next(r) && at.next(a)) {
        if (a.has_q) {
            e.push_back(error_arcsec(a.q_crf_icrf, r.q_crf_icrf));
        }
    }
    n = e.size();
    Eigen::Vector3d mean = Eigen::Vector3d::Zero();
    for (const auto& x : e) {
        mean += x / static_cast<double>(n);
    }
    Eigen::Vector3d ss = Eigen::Vector3d::Zero();
    for (const auto& x : e) {
        ss += (x - mean).cwiseProduct(x - mean);
    }
    return (ss / static_cast<double>(n)).cwiseSqrt();
}

TEST(GracefoImport, AlignAndCombineAgreeWithJplWithinThreeArcsec) {
    for (const char sat : {'C', 'D'}) {
        const fs::path dir = test::scratch_dir(std::string("gracefo_jpl_") + sat);
        ASSERT_EQ(run_in(import_args(sat), dir).exit_code, 0);
        ASSERT_EQ(run_in("align --in sol.csv --mountings m.csv --out m2.csv --min-epochs 30 --noise-window 0 > "
                         "align.txt",
                         dir)
                      .exit_code,
                  0)
            << test::slurp(dir / "stderr.txt");
        ASSERT_EQ(run_in("combine --in sol.csv --mountings m2.csv --out comb.csv", dir).exit_code, 0);
        std::size_t n = 0;
        const Eigen::Vector3d rms = rms_against_jpl(dir, "comb.csv", n);
        EXPECT_GE(n, 15U) << sat;  // SCA1B's times within the 16.5 s of SCA1A records
        EXPECT_LT(rms.maxCoeff(), 3.0) << sat << ": " << rms.transpose();
        // The worked example's last step reports the same comparison.
        const test::CliRun stats = run_in("stats --combined at.csv --truth-attitude ref.csv > stats.txt", dir);
        EXPECT_EQ(stats.exit_code, 0) << stats.err;
        EXPECT_NE(test::slurp(dir / "stats.txt").find("ABC "), std::string::npos);
        // Mutation check: the boresight weighted as the cross axes (each
        // head's sigma_about set to its sigma_cross) fails the bound.
        test::rewrite_csv_rows(dir / "m2.csv", dir / "equal.csv", [](const std::string& line, std::ostream& out) {
            const std::size_t last = line.rfind(',');
            const std::size_t cross = line.rfind(',', last - 1);
            out << line.substr(0, last) << ',' << line.substr(cross + 1, last - cross - 1) << '\n';
        });
        ASSERT_EQ(run_in("combine --in sol.csv --mountings equal.csv --out equal-comb.csv", dir).exit_code, 0);
        EXPECT_GT(rms_against_jpl(dir, "equal-comb.csv", n).maxCoeff(), 3.0) << sat;
    }
}

// The SCA1A file of GRACE C split: its header (through the end marker) and records.
struct Sca1aText {
    std::string header;
    std::vector<std::string> lines;
    Sca1aText() {
        std::ifstream in(product("SCA1A", 'C'));
        std::string line;
        bool in_header = true;
        while (std::getline(in, line)) {
            if (in_header) {
                header += line + "\n";
                in_header = line.rfind("# End of YAML header", 0) != 0;
            } else {
                lines.push_back(line);
            }
        }
    }
    std::string with(std::size_t i, const std::string& replacement) const {
        std::string s = header;
        for (std::size_t k = 0; k < lines.size(); ++k) {
            s += (k == i ? replacement : lines[k]) + "\n";
        }
        return s;
    }
};

TEST(GracefoImport, OldHeadersAndSeveralFilesGiveTheSameSolutions) {
    const fs::path dir = test::scratch_dir("gracefo_headers");
    const Sca1aText sca;
    std::ofstream(dir / "old.txt") << "PRODUCER AGENCY               : NASA\nEND OF HEADER\n"
                                   << sca.with(99, sca.lines[99]).substr(sca.header.size());
    std::string first;
    std::string second;
    for (std::size_t k = 0; k < sca.lines.size(); ++k) {
        (k < 50 ? first : second) += sca.lines[k] + "\n";
    }
    std::ofstream(dir / "a.txt") << sca.header << first;
    std::ofstream(dir / "b.txt") << sca.header << second;
    const std::string q = " --qsa1b " + product("QSA1B", 'C') + " --mountings m.csv";
    ASSERT_EQ(run_in("import gracefo --sca1a " + product("SCA1A", 'C') + q + " --out whole.csv", dir).exit_code, 0);
    ASSERT_EQ(run_in("import gracefo --sca1a old.txt" + q + " --out old.csv", dir).exit_code, 0);
    ASSERT_EQ(run_in("import gracefo --sca1a b.txt --sca1a a.txt" + q + " --out split.csv", dir).exit_code, 0);
    const std::string whole = test::slurp(dir / "whole.csv");
    EXPECT_EQ(test::slurp(dir / "old.csv"), whole);
    EXPECT_EQ(test::slurp(dir / "split.csv"), whole);
}

TEST(GracefoImport, TheQualityBitsMakeTheFlags) {
    const fs::path dir = test::scratch_dir("gracefo_flags");
    const Sca1aText sca;
    const std::string rec = sca.lines[3];  // sca_mode 11000001 qualflg 11000000: flags 0
    const std::string head = rec.substr(0, rec.size() - 17);
    struct Case {
        std::string mode_quality;
        long long flags;
    };
    const std::vector<Case> cases = {
        {"11000001 11000000", 0},  // valid, orbit (aberration) correction used
        {"11000000 11000000", 4},  // sca_mode: invalid
        {"11000001 11000001", 4},  // qualflg bit 0 set: invalid (read inverted, as JPL's format and GROOPS)
        {"11001001 11000000", 2},  // a non-stellar object
        {"11000001 11001000", 2},  {"10000001 11000000", 8},  // the tracker did not correct aberration
        {"11000101 11000000", 16},                            // "add 1/4 of the integration period": unknown, not clean
        {"11000001 11000100", 16}, {"10001100 11000001", 4 + 2 + 8 + 16},
        {"01000011 10010000", 0},  // sequence, precision, 1-Hz mode: no quality
    };
    std::string text = sca.header;
    for (const Case& c : cases) {
        text += head + c.mode_quality + "\n";
    }
    std::ofstream(dir / "flags.txt") << text;
    ASSERT_EQ(
        run_in("import gracefo --sca1a flags.txt --qsa1b " + product("QSA1B", 'C') + " --out sol.csv --mountings m.csv",
               dir)
            .exit_code,
        0)
        << test::slurp(dir / "stderr.txt");
    std::string storage;
    const std::vector<host::SolutionRecord> got = test::read_records((dir / "sol.csv").string(), storage);
    ASSERT_EQ(got.size(), cases.size());
    for (std::size_t i = 0; i < cases.size(); ++i) {
        EXPECT_EQ(got[i].flags, cases[i].flags) << cases[i].mode_quality;
    }
}

TEST(GracefoImport, EveryBadRecordIsNamedByFileAndLineAndNothingIsWritten) {
    const fs::path dir = test::scratch_dir("gracefo_bad");
    const Sca1aText sca;
    const auto first_line =
        static_cast<std::size_t>(std::count(sca.header.begin(), sca.header.end(), '\n')) + 1;  // of record 0
    const std::string rec = sca.lines[3];  // 738849600 529976 C 1 P qw qx qy qz 0 46 1 0 0 11000001 11000000
    const auto replace = [&rec](const std::string& from, const std::string& to) {
        std::string r = rec;
        r.replace(r.find(from), from.size(), to);
        return r;
    };
    struct Case {
        std::string text;  // the SCA1A file
        std::string want;  // after "bad.txt:"
    };
    const std::string at = std::to_string(first_line + 3) + ":";
    const std::vector<Case> cases = {
        {sca.with(3, rec + " 7"),
         at + std::to_string(rec.size() + 2) + ": expected 16 fields of a SCA1A record, found 17"},
        {sca.with(3, replace(" C 1 P ", " C 4 P ")), at + "20: sca_id (1, 2 or 3): "},
        {sca.with(3, replace("-0.2798879596590735", "-0.3798879596590735")), at + "24: the quaternion is not unit"},
        {sca.with(3, replace("529976", "1000000")), at + "11: rcvtime_frac: "},
        {sca.with(3, replace("738849600 529976", "738849599 529976")), at + "1: the time goes back"},
        {sca.with(3, replace(" C 1 P ", " D 1 P ")), at + "18: a record of GRACE D among those of GRACE C"},
        {sca.with(3, replace("11000001 11000000", "11000001 1100000x")),
         at + std::to_string(rec.rfind(' ') + 2) + ": qualflg: expected eight binary digits"},
        {sca.with(3, replace("738849600 529976", "738860000 529976")),
         at + "1: the time 738860000.529976 s is not covered by"},
        {sca.lines[0] + "\n", " no end of a GRACE-FO Level-1 header"},
    };
    for (const Case& c : cases) {
        std::ofstream(dir / "bad.txt") << c.text;
        const test::CliRun r = run_in("import gracefo --sca1a bad.txt --qsa1b " + product("QSA1B", 'C') + " --tim1b " +
                                          product("TIM1B", 'C') + " --out sol.csv --mountings m.csv",
                                      dir);
        EXPECT_NE(r.exit_code, 0) << c.want;
        EXPECT_NE(r.err.find("bad.txt:" + c.want), std::string::npos) << "wanted bad.txt:" << c.want << "\n" << r.err;
        EXPECT_FALSE(fs::exists(dir / "sol.csv") || fs::exists(dir / "m.csv")) << c.want;
    }
    // QSA1B with a head twice; SCA1B whose time goes back.
    std::ofstream(dir / "qsa.txt")
        << "END OF HEADER\n580219200 C 1 1 0 0 0 0 00000000\n580219200 C 1 1 0 0 0 0 00000000\n";
    const test::CliRun twice = run_in(
        "import gracefo --sca1a " + product("SCA1A", 'C') + " --qsa1b qsa.txt --out sol.csv --mountings m.csv", dir);
    EXPECT_NE(twice.err.find("qsa.txt:3:13: a second mounting of head A (the first on line 2)"), std::string::npos)
        << twice.err;
    std::ofstream(dir / "sca1b.txt")
        << "# End of YAML header\n738849601 C 23 1 0 0 0 0 00000000\n738849600 C 23 1 0 0 0 0 00000000\n";
    const test::CliRun back =
        run_in("import gracefo --sca1a " + product("SCA1A", 'C') + " --qsa1b " + product("QSA1B", 'C') +
                   " --sca1b sca1b.txt --reference ref.csv --out sol.csv --mountings m.csv",
               dir);
    EXPECT_NE(back.err.find("sca1b.txt:3:1: the time goes back"), std::string::npos) << back.err;
    EXPECT_FALSE(fs::exists(dir / "sol.csv") || fs::exists(dir / "ref.csv"));
    // TIM1B with a record short of a field; CLK1B whose time goes back.
    std::ofstream(dir / "tim.txt") << "# End of YAML header\n738849605 C 0 738849605 0 -1 -1\n";
    std::ofstream(dir / "clk.txt") << "# End of YAML header\n738849610 C -1 -0.0167 0 0 0 00000000\n"
                                   << "738849600 C -1 -0.0167 0 0 0 00000000\n";
    const std::string sol = " --sca1a " + product("SCA1A", 'C') + " --qsa1b " + product("QSA1B", 'C');
    const test::CliRun tim = run_in("import gracefo" + sol + " --tim1b tim.txt --out sol.csv --mountings m.csv", dir);
    EXPECT_NE(tim.err.find("tim.txt:2:32: expected 8 fields of a TIM1B record, found 7"), std::string::npos) << tim.err;
    const test::CliRun clk = run_in("import gracefo" + sol + " --clk1b clk.txt --out sol.csv --mountings m.csv", dir);
    EXPECT_NE(clk.err.find("clk.txt:3:1: the time goes back"), std::string::npos) << clk.err;
    // More bad products: each refused naming the file (and line), nothing written.
    std::ofstream(dir / "empty_tim.txt") << "# End of YAML header\n";
    std::ofstream(dir / "gap_tim.txt") << "# End of YAML header\n738849590 C 0 738849590 0 -1 -1 00000100\n"
                                       << "738849598 C 0 738849598 0 -1 -1 00000100\n"
                                       << "738849606 C 0 738849606 0 -1 -1 00000100\n"
                                       << "738849700 C 0 738849700 0 -1 -1 00000100\n";
    std::ofstream(dir / "qsa_short.txt") << "END OF HEADER\n580219200 C 1 1 0 0 0 00000000\n";
    std::ofstream(dir / "qsa_norm.txt") << "END OF HEADER\n580219200 C 1 1 0.1 0 0 0 00000000\n";
    std::ofstream(dir / "sca1b_norm.txt") << "# End of YAML header\n738849601 C 23 0.9 0 0 0 0 00000000\n";
    const std::string sca1a = " --sca1a " + product("SCA1A", 'C');
    const std::string qsa = " --qsa1b " + product("QSA1B", 'C');
    const std::vector<std::pair<std::string, std::string>> more = {
        {sca1a + qsa + " --tim1b empty_tim.txt", "TIM1B: 0 usable records in empty_tim.txt"},
        // the 37th record (line 184 + 36), the first after 738849606: in the gap up to 738849700
        {sca1a + qsa + " --tim1b gap_tim.txt",
         "SCA1A_2023-06-01_C_04.txt:220:1: the time 738849606.029988 s is not covered by gap_tim.txt"},
        {sca1a + " --qsa1b qsa_short.txt", "qsa_short.txt:2:31: expected 9 fields of a QSA1B record, found 8"},
        {sca1a + " --qsa1b qsa_norm.txt", "qsa_norm.txt:2:15: the quaternion is not unit"},
        {sca1a + qsa + " --sca1b sca1b_norm.txt --reference ref.csv",
         "sca1b_norm.txt:2:16: the quaternion is not unit"},
    };
    for (const auto& [args, want] : more) {
        const test::CliRun r = run_in("import gracefo" + args + " --out sol.csv --mountings m.csv", dir);
        EXPECT_NE(r.exit_code, 0) << args;
        EXPECT_NE(r.err.find(want), std::string::npos) << "wanted " << want << "\n" << r.err;
    }
    EXPECT_FALSE(fs::exists(dir / "sol.csv") || fs::exists(dir / "m.csv") || fs::exists(dir / "ref.csv"));
}

}  // namespace
}  // namespace ascorr
