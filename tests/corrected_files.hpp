// tests/corrected_files.hpp: two corrected files (docs/contract.md,
// "Corrected file") compared row by row.
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "ascorr/core/quaternion.hpp"
#include "cli_run.hpp"
#include "test_support.hpp"

namespace ascorr::test {

// The corrected rows of a file, by line: status and quaternion.
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

}  // namespace ascorr::test
