// tests/solutions_records.hpp: every record of a solutions file, for the
// test programs and for the target's vector generator (which has no GoogleTest).
#pragma once

#include <string>
#include <vector>

#include "ascorr_host/formats/csv.hpp"
#include "ascorr_host/formats/solutions_csv.hpp"

namespace ascorr::test {

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

}  // namespace ascorr::test
