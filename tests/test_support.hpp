// tests/test_support.hpp: shared helpers of the test programs.
#pragma once

#include <gtest/gtest.h>

#include <unistd.h>
#include <Eigen/Geometry>
#include <cmath>
#include <cstdint>

#include <filesystem>
#include <random>
#include <string>
#include <vector>

#include "ascorr/ascorr.hpp"
#include "ascorr_host/formats/csv.hpp"
#include "ascorr_host/formats/solutions_csv.hpp"

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

// All records of a solutions file (the host reader is itself tested in test_formats).
inline std::vector<host::SolutionRecord> read_records(const std::string& path, std::string& storage) {
    storage = host::read_text_file(path);
    host::SolutionsReader r(path, storage);
    std::vector<host::SolutionRecord> out;
    host::SolutionRecord rec;
    while (r.next(rec)) {
        out.push_back(rec);
    }
    return out;
}

// A fresh, empty directory for one test.
inline std::filesystem::path scratch_dir(const std::string& name) {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    auto dir = std::filesystem::temp_directory_path() /
               ("ascorr-test-" + std::to_string(::getpid()) + "-" + name + "-" + info->name());
    std::filesystem::remove_all(dir);
    std::filesystem::create_directories(dir);
    return dir;
}

}  // namespace ascorr::test
