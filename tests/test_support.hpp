// tests/test_support.hpp: shared helpers of the test programs.
#pragma once

#include <gtest/gtest.h>

#include <unistd.h>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdlib>

#include <filesystem>
#include <fstream>
#include <optional>
#include <ostream>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "ascorr/ascorr.hpp"
#include "ascorr_host/formats/csv.hpp"
#include "ascorr_host/formats/solutions_csv.hpp"
#include "solutions_records.hpp"

namespace ascorr::test {

inline std::string data_path(const std::string& name) {
    return std::string(ASCORR_TEST_DATA) + "/" + name;
}

inline Eigen::Quaterniond to_eigen(const Quaternion<double>& q) {
    return {q.w, q.x, q.y, q.z};
}
inline Quaternion<double> from_eigen(const Eigen::Quaterniond& q) {
    return {q.w(), q.x(), q.y(), q.z()};
}

// Rotation angle between two attitudes, arcsec (sign of q ignored). Uses the
// vector part of a* ⊗ b, which keeps full precision for tiny angles.
inline double angle_arcsec(const Eigen::Quaterniond& a, const Eigen::Quaterniond& b) {
    const Eigen::Quaterniond d = a.conjugate() * b;
    const double s = std::min(1.0, d.vec().norm() / d.norm());
    return 2.0 * std::asin(s) * kRadToArcsec;
}
inline double angle_arcsec(const Quaternion<double>& a, const Quaternion<double>& b) {
    return angle_arcsec(to_eigen(a), to_eigen(b));
}

// Angle between two directions, arcsec, precise for tiny angles.
inline double angle_arcsec(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
    return std::atan2(a.cross(b).norm(), a.dot(b)) * kRadToArcsec;
}

inline Eigen::Vector3d random_unit_vector(std::mt19937_64& rng) {
    std::normal_distribution<double> n(0.0, 1.0);
    Eigen::Vector3d v(n(rng), n(rng), n(rng));
    return v.normalized();
}

inline Eigen::Quaterniond random_attitude(std::mt19937_64& rng) {
    std::normal_distribution<double> n(0.0, 1.0);
    Eigen::Quaterniond q(n(rng), n(rng), n(rng), n(rng));
    q.normalize();
    return q;
}

// The message of the E that f() throws; nothing when it throws nothing.
template <typename E, typename F>
std::optional<std::string> message_thrown(F&& f) {
    try {
        f();
    } catch (const E& e) {
        return std::string(e.what());
    }
    return std::nullopt;
}

// The message of the E that f() throws; when it throws nothing, a failure
// `accepted` and "".
template <typename E, typename F>
std::string thrown_by(F&& f, const std::string& accepted) {
    const std::optional<std::string> m = message_thrown<E>(std::forward<F>(f));
    if (!m) {
        ADD_FAILURE() << accepted;
    }
    return m.value_or("");
}

// The message of the E that f() throws; `none` when it throws nothing.
template <typename E, typename F>
std::string message_of(F&& f, const std::string& none) {
    return message_thrown<E>(std::forward<F>(f)).value_or(none);
}

// Copies the CSV file `from` to `to`: its header line as it is, then what
// row(line, out) writes for each other line (a line it writes nothing for is dropped).
template <typename Row>
void rewrite_csv_rows(const std::filesystem::path& from, const std::filesystem::path& to, Row row) {
    std::ifstream in(from);
    std::ofstream out(to);
    std::string line;
    std::getline(in, line);
    out << line << '\n';
    while (std::getline(in, line)) {
        row(line, out);
    }
}

// Removes the process' scratch directories when the whole test program
// passed (a failure keeps them all for the diagnosis; so does
// ASCORR_KEEP_SCRATCH=1). At the program's end, not the test's: some missions
// are simulated once into a directory and shared by the tests that follow.
// Without it every run left its directories in the temporary folder (their
// names carry the process id), tens of GB over many runs.
class ScratchCleaner : public ::testing::EmptyTestEventListener {
public:
    void add(const std::filesystem::path& dir) { dirs_.push_back(dir); }
    void OnTestProgramEnd(const ::testing::UnitTest& unit) override {
        const char* keep = std::getenv("ASCORR_KEEP_SCRATCH");
        if (!unit.Passed() || (keep != nullptr && std::string(keep) == "1")) {
            return;
        }
        for (const auto& d : dirs_) {
            std::error_code ec;
            std::filesystem::remove_all(d, ec);
        }
    }

private:
    std::vector<std::filesystem::path> dirs_;
};

// The one cleaner of the process, appended to gtest's listeners (which own
// it) at the first scratch directory.
inline ScratchCleaner& scratch_cleaner() {
    static ScratchCleaner* cleaner = [] {
        auto* c = new ScratchCleaner();
        ::testing::UnitTest::GetInstance()->listeners().Append(c);
        return c;
    }();
    return *cleaner;
}

// A fresh, empty directory for one test; removed when the program passes.
// One level: a parameterized test's name ("CleanLink/qemu_m3") has its '/'
// replaced, or the cleaner would remove the leaf and leave its parent.
inline std::filesystem::path scratch_dir(const std::string& name) {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    std::string test = info->name();
    std::replace(test.begin(), test.end(), '/', '_');
    auto dir = std::filesystem::temp_directory_path() /
               ("ascorr-test-" + std::to_string(::getpid()) + "-" + name + "-" + test);
    std::filesystem::remove_all(dir);
    std::filesystem::create_directories(dir);
    scratch_cleaner().add(dir);
    return dir;
}

}  // namespace ascorr::test
