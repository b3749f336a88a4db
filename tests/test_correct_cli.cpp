// `ascorr correct` end to end: the worked examples through the executable,
// status bits, bad rows, all-or-nothing output.
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

#include "cli_run.hpp"
#include "test_support.hpp"

namespace ascorr::test {
namespace {

namespace fs = std::filesystem;

double max_error(const fs::path& got, const std::string& expected_name) {
    std::string a;
    std::string b;
    const auto g = read_records(got.string(), a);
    const auto e = read_records(data_path(expected_name), b);
    EXPECT_EQ(g.size(), e.size());
    double worst = 0.0;
    for (std::size_t i = 0; i < std::min(g.size(), e.size()); ++i) {
        EXPECT_EQ(g[i].t, e[i].t);  // input order kept
        worst = std::max(worst, angle_arcsec(g[i].q_chu_icrf, e[i].q_chu_icrf));
    }
    return worst;
}

TEST(CorrectCli, WorkedExamplesAllStages) {
    const fs::path dir = scratch_dir("cli");
    const std::string in = data_path("solutions.csv");
    const std::string model = data_path("model_table2.csv");
    ASSERT_EQ(
        run_here("correct --in " + in + " --out " + (dir / "ab.csv").string() + " --no-thermal --model " + model, dir)
            .exit_code,
        0);
    ASSERT_EQ(
        run_here("correct --in " + in + " --out " + (dir / "th.csv").string() + " --no-aberration --model " + model,
                 dir)
            .exit_code,
        0);
    ASSERT_EQ(
        run_here("correct --in " + in + " --out " + (dir / "both.csv").string() + " --model " + model, dir).exit_code,
        0);
    EXPECT_LE(max_error(dir / "ab.csv", "expected_aberration_only.csv"), 1e-6);
    EXPECT_LE(max_error(dir / "th.csv", "expected_thermal_only.csv"), 1e-6);
    EXPECT_LE(max_error(dir / "both.csv", "expected_both.csv"), 1e-6);
    // Without --model: aberration only, status 1.
    ASSERT_EQ(run_here("correct --in " + in + " --out " + (dir / "nomodel.csv").string(), dir).exit_code, 0);
    EXPECT_LE(max_error(dir / "nomodel.csv", "expected_aberration_only.csv"), 1e-6);
    const auto l = lines_of_file(dir / "both.csv");
    ASSERT_EQ(l.size(), 13U);
    EXPECT_EQ(l[0], "t,chu,qw,qx,qy,qz,t_chu,t_029,t_032,vx,vy,vz,flags,confidence,status");
    EXPECT_EQ(l[1].substr(l[1].rfind(',')), ",3");
    EXPECT_EQ(lines_of_file(dir / "ab.csv")[1].substr(l[1].rfind(',')), ",1");
    EXPECT_EQ(lines_of_file(dir / "th.csv")[1].substr(l[1].rfind(',')), ",2");
    // All other fields verbatim.
    const std::string tail = ",19.673,-7.351,-17.769,2.366838,7.186540,0.715348,0,1.00,3";
    EXPECT_EQ(l[5].substr(0, 16), "494599640.318,B,");
    ASSERT_GE(l[5].size(), tail.size());
    EXPECT_EQ(l[5].substr(l[5].size() - tail.size()), tail);
}

TEST(CorrectCli, FloatScalarWithinBound) {
    const fs::path dir = scratch_dir("cli");
    ASSERT_EQ(run_here("correct --scalar float --in " + data_path("solutions.csv") + " --out " +
                           (dir / "f.csv").string() + " --model " + data_path("model_table2.csv"),
                       dir)
                  .exit_code,
              0);
    EXPECT_LE(max_error(dir / "f.csv", "expected_both.csv"), 0.05);
}

TEST(CorrectCli, EveryRowKeptWithItsStatus) {
    const fs::path dir = scratch_dir("cli");
    const std::string h = "t,chu,qw,qx,qy,qz,t_chu,t_029,t_032,vx,vy,vz,flags,confidence,note\n";
    write(dir / "in.csv", h + "447534187.831,A,0.5,0.5,0.5,0.5,3,-9,-19,-7,0.7,-1.7,0,1,ok\n"         // 3
                              "447534187.831,B,0.5,0.5,0.5,0.5,,-9,-19,-7,0.7,-1.7,0,1,no_t\n"        // 1|8
                              "447534187.831,C,0.5,0.5,0.5,0.5,3,-9,-19,,,,4,9,no_v\n"                // 2|4
                              "447534187.831,A,nan,0.5,0.5,0.5,3,-9,-19,-7,0.7,-1.7,0,1,nan_q\n"      // 16
                              "447534187.831,A,0.6,0.5,0.5,0.5,3,-9,-19,-7,0.7,-1.7,0,1,not_unit\n"   // 16
                              "447534187.831,E,0.5,0.5,0.5,0.5,3,-9,-19,-7,0.7,-1.7,0,1,bad_head\n"   // 16
                              "447534187.831,D,0.5,0.5,0.5,0.5,3,-9,-19,-7,0.7,-1.7,0,1,no_model\n"   // 1|256
                              "447534187.831,A,-0.5,-0.5,-0.5,-0.5,3,-9,-19,-7,0.7,-1.7,0,1,neg\n"    // 3
                              "447534187.831,A,0.5,0.5,0.5,0.5,3,-9,-19,4e5,0,0,0,1,v_gt_c\n"         // 2|4|32
                              "447534187.831,A,0.5,0.5,0.5,0.5,3,-9,-19,-7,,-1.7,0,1,v_partial\n"     // 2|4|32
                              "447534187.831,A,0.5,0.5,0.5,0.5,3,-9,999,-7,0.7,-1.7,0,1,t_short\n");  // 1|8|64
    const CliRun r = run_here("correct --in " + (dir / "in.csv").string() + " --out " + (dir / "out.csv").string() +
                                  " --model " + data_path("model_table2.csv"),
                              dir);
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const auto l = lines_of_file(dir / "out.csv");
    ASSERT_EQ(l.size(), 12U);
    EXPECT_EQ(l[0], "t,chu,qw,qx,qy,qz,t_chu,t_029,t_032,vx,vy,vz,flags,confidence,note,status");
    const auto status_of = [&](std::size_t i) { return l[i].substr(l[i].rfind(',') + 1); };
    const char* want[] = {"3", "9", "6", "16", "16", "16", "257", "3", "38", "38", "73"};
    for (std::size_t i = 0; i < 11; ++i) {
        EXPECT_EQ(status_of(i + 1), want[i]) << l[i + 1];
    }
    // Rejected rows come back exactly as written.
    EXPECT_EQ(l[4], "447534187.831,A,nan,0.5,0.5,0.5,3,-9,-19,-7,0.7,-1.7,0,1,nan_q,16");
    EXPECT_EQ(l[5], "447534187.831,A,0.6,0.5,0.5,0.5,3,-9,-19,-7,0.7,-1.7,0,1,not_unit,16");
    // A negated quaternion comes out canonical (w >= 0) and equal to the positive one.
    EXPECT_EQ(l[8].substr(0, l[8].find(",3,-9")), l[1].substr(0, l[1].find(",3,-9")));
    // Each defect is named with file and line.
    const std::string f = (dir / "in.csv").string();
    EXPECT_NE(r.err.find(f + ":5: quaternion is not finite"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find(f + ":6: quaternion is not unit"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find(f + ":7: chu 'E' is not a camera head"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find(f + ":8: the model has no coefficients for chu 'D'"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find(f + ":10: observer speed"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find(f + ":11: only 2 of vx,vy,vz"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find(f + ":12: temperature outside"), std::string::npos) << r.err;
}

TEST(CorrectCli, MalformedRowStopsAndWritesNothing) {
    const fs::path dir = scratch_dir("cli");
    std::string text = lines_of_file(data_path("solutions.csv"))[0] + "\n";
    const auto src = lines_of_file(data_path("solutions.csv"));
    for (std::size_t i = 1; i < src.size(); ++i) {
        text += (i == 7 ? src[i].substr(0, 40) : src[i]) + "\n";  // line 8 truncated
    }
    write(dir / "in.csv", text);
    write(dir / "out.csv", "previous content\n");
    const CliRun r =
        run_here("correct --in " + (dir / "in.csv").string() + " --out " + (dir / "out.csv").string(), dir);
    EXPECT_NE(r.exit_code, 0);
    EXPECT_NE(r.err.find((dir / "in.csv").string() + ":8:"), std::string::npos) << r.err;
    EXPECT_EQ(lines_of_file(dir / "out.csv"), std::vector<std::string>{"previous content"});  // untouched
    for (const auto& e : fs::directory_iterator(dir)) {
        EXPECT_EQ(e.path().string().find(".tmp-"), std::string::npos) << "temporary file left behind";
    }
    // --skip-bad: the bad row is reported and dropped, the rest written.
    const CliRun s =
        run_here("correct --skip-bad --in " + (dir / "in.csv").string() + " --out " + (dir / "out.csv").string(), dir);
    EXPECT_EQ(s.exit_code, 0) << s.err;
    EXPECT_EQ(lines_of_file(dir / "out.csv").size(), 12U);
    EXPECT_NE(s.err.find(":8:"), std::string::npos);
    EXPECT_NE(s.err.find("1 malformed rows skipped"), std::string::npos) << s.err;
}

TEST(CorrectCli, BadInvocationsFailCleanly) {
    const fs::path dir = scratch_dir("cli");
    EXPECT_EQ(run_here("correct --in " + data_path("solutions.csv"), dir).exit_code, 2);  // --out missing
    EXPECT_EQ(
        run_here("correct --in " + data_path("solutions.csv") + " --out " + (dir / "o.csv").string() + " --scalar quad",
                 dir)
            .exit_code,
        2);
    const CliRun missing =
        run_here("correct --in " + (dir / "nope.csv").string() + " --out " + (dir / "o.csv").string(), dir);
    EXPECT_EQ(missing.exit_code, 1);
    EXPECT_NE(missing.err.find("nope.csv"), std::string::npos);
    write(dir / "m.csv", "chu,axis,c0,c1,c2,c3\nA,alpha,1,2,3\n");
    const CliRun bad_model = run_here("correct --in " + data_path("solutions.csv") + " --out " +
                                          (dir / "o.csv").string() + " --model " + (dir / "m.csv").string(),
                                      dir);
    EXPECT_EQ(bad_model.exit_code, 1);
    EXPECT_NE(bad_model.err.find("m.csv:2:"), std::string::npos) << bad_model.err;
    EXPECT_FALSE(fs::exists(dir / "o.csv"));
}

}  // namespace
}  // namespace ascorr::test
