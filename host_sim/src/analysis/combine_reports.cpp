#include <string>

#include "ascorr_host/formats/csv.hpp"
#include "ascorr_host/formats/solutions_csv.hpp"
#include "ascorr_text/c_format.hpp"
#include "ascorr_text/input_name.hpp"
#include "combine_parts.hpp"

namespace ascorr::host::detail {

namespace {

std::string time_text(double t) {
    char buf[48];
    text::c_snprintf(buf, sizeof buf, "%.3f", t);
    return buf;
}

}  // namespace

std::string LeftOutReports::where(std::size_t line) const {
    return text::input_name(file_) + ":" + std::to_string(line) + ": ";
}

void LeftOutReports::no_epoch(std::size_t line, double t) {
    diag_.report("in no epoch",
                 where(line) + "t = " + number_text(t) + " s has no millisecond key: the row is in no epoch");
}

void LeftOutReports::epoch(const std::vector<Kept>& rows, const std::vector<LeftOut>& why, StatusBits stages) {
    std::size_t first = 0;  // the first row of rows[i]'s head
    for (std::size_t i = 0; i < rows.size(); ++i) {
        first = rows[i].head == rows[first].head ? first : i;
        if (why[i] == LeftOut::kDuplicate && i != first) {
            diag_.report("two rows of one head", where(rows[i].line) + "a second row of CHU " +
                                                     head_name(rows[i].head) + " at t = " + time_text(rows[i].t) +
                                                     " (the first on line " + std::to_string(rows[first].line) +
                                                     "): both left out (status 4)");
        }
    }
    for (std::size_t i = 0; i < rows.size(); ++i) {
        if (why[i] == LeftOut::kStageMissing) {
            const Kept& k = rows[i];
            diag_.report("stage missing", where(k.line) + "CHU " + head_name(k.head) + " at t = " + time_text(k.t) +
                                              ": status " + std::to_string(k.stages) +
                                              " lacks a stage applied to another head of the epoch (status " +
                                              std::to_string(stages) + "): left out (status 4)");
        }
    }
}

void LeftOutReports::row(const Kept& k) {
    if (k.why == LeftOut::kNotInMountings) {
        diag_.report("not in the mountings", where(k.line) + "CHU " + head_name(k.head) + " at t = " + time_text(k.t) +
                                                 " is not in the mountings: left out (status 4)");
    } else if (k.why == LeftOut::kNotAHead) {
        diag_.report("not a head",
                     where(k.line) + "chu is not a camera head (" + kHeadChoices.text + "): left out (status 4)");
    } else if (k.why == LeftOut::kNotUnit) {
        diag_.report("quaternion not unit", where(k.line) + "CHU " + head_name(k.head) + " at t = " + time_text(k.t) +
                                                ": the quaternion is not unit: left out (status 4)");
    } else if (k.why == LeftOut::kInconsistent) {
        diag_.report("inconsistent", where(k.line) + "CHU " + head_name(k.head) + " at t = " + time_text(k.t) +
                                         " disagrees with the other heads beyond the combiner's gate: left out "
                                         "(status 4)");
    }
}

}  // namespace ascorr::host::detail
