// tests/corrected_files.hpp: two corrected files (docs/contract.md,
// "Corrected file") compared row by row, and a replay on the loopback target
// compared with `ascorr correct`.
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <iostream>
#include <map>
#include <ostream>
#include <sstream>
#include <string>
#include <vector>

#include "ascorr/core/quaternion.hpp"
#include "ascorr_host/link/replay.hpp"
#include "cli_run.hpp"
#include "test_support.hpp"

namespace ascorr::test {

// The corrected rows of a file, by t and head (rows alike in both are one
// key, the last): status and quaternion.
struct Corrected {
    std::string status;
    Quaternion<double> q;
};
inline std::map<std::string, Corrected> corrected_of(const std::filesystem::path& file) {
    std::map<std::string, Corrected> out;
    const std::vector<std::string> lines = lines_of_file(file);
    for (std::size_t i = 1; i < lines.size(); ++i) {
        std::vector<std::string> f;
        std::stringstream ss(lines[i]);
        for (std::string c; std::getline(ss, c, ',');) {
            f.push_back(c);
        }
        out[f[0] + "," + f[1]] = {f.back(), {std::stod(f[2]), std::stod(f[3]), std::stod(f[4]), std::stod(f[5])}};
    }
    return out;
}

// The largest angle between two corrected files' rows (arcsec); statuses must agree.
inline double largest_difference(const std::filesystem::path& a, const std::filesystem::path& b) {
    const auto ra = corrected_of(a);
    const auto rb = corrected_of(b);
    EXPECT_EQ(ra.size(), rb.size());
    double worst = 0.0;
    for (const auto& [key, x] : ra) {
        const auto it = rb.find(key);
        if (it == rb.end()) {
            ADD_FAILURE() << key << " missing from " << b;
            continue;
        }
        EXPECT_EQ(x.status, it->second.status) << key;
        worst = std::max(worst, angle_arcsec(x.q, it->second.q));
    }
    return worst;
}

// dir/s.csv replayed on the loopback target (float) with dir/`model` into
// dir/r.csv, and corrected by `ascorr correct` with it (dir/c.csv) and with
// dir/m.csv (c0.csv: what `model` adds left out): every answer back, bit for
// bit as the host's pipeline, within the float bound of the replay tests
// (0.05″) of the double reference and of correct's file, every status the
// same; the mutation check: c.csv and c0.csv more than ten bounds apart.
// Returns the replay's summary; prints it as `what`.
inline host::ReplaySummary expect_replay_as_correct(const std::filesystem::path& dir, const std::string& model,
                                                    const std::string& what) {
    EXPECT_EQ(run_in("correct --in s.csv --model " + model + " --out c.csv > /dev/null 2>&1", dir).exit_code, 0);
    EXPECT_EQ(run_in("correct --in s.csv --model m.csv --out c0.csv > /dev/null 2>&1", dir).exit_code, 0);
    host::ReplayOptions o;
    o.target = "loopback-float";
    o.in = (dir / "s.csv").string();
    o.model = (dir / model).string();
    o.out = (dir / "r.csv").string();
    std::ostringstream log;
    const host::ReplaySummary s = host::replay(o, log);
    EXPECT_EQ(s.returned, s.frames);
    EXPECT_EQ(s.mismatches, 0U);
    EXPECT_LE(s.max_error_arcsec, 0.05);
    const double against_correct = largest_difference(dir / "r.csv", dir / "c.csv");
    EXPECT_LE(against_correct, 0.05);
    EXPECT_GT(largest_difference(dir / "c.csv", dir / "c0.csv"), 10 * 0.05);
    std::cout << what << " replayed against correct: " << against_correct << " arcsec; " << host::to_json(s) << "\n";
    return s;
}

}  // namespace ascorr::test
