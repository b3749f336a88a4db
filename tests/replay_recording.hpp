// tests/replay_recording.hpp: a recorded solutions file for the replay tests.
#pragma once

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "test_support.hpp"

namespace ascorr::test {

// A recorded file of n rows cycling through the 12 worked examples, three
// rows per second (so the velocity changes every third row).
inline std::string make_recording(const std::filesystem::path& dir, int n) {
    std::vector<std::string> lines;
    std::istringstream ss(host::read_text_file(data_path("solutions.csv")));
    for (std::string l; std::getline(ss, l);) {
        lines.push_back(l);
    }
    std::string text = lines[0] + "\n";
    for (int i = 0; i < n; ++i) {
        const std::string& l = lines[1 + static_cast<std::size_t>(i % 12)];
        text += std::to_string(450000000 + i / 3) + l.substr(l.find(',')) + "\n";
    }
    const auto path = (dir / "rec.csv").string();
    std::ofstream(path) << text;
    return path;
}

}  // namespace ascorr::test
