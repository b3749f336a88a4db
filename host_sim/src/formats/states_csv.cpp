#include "ascorr_host/formats/states_csv.hpp"

#include <cmath>
#include <cstdio>
#include <string_view>

#include "ascorr_host/formats/csv.hpp"
#include "ascorr_text/input_error.hpp"
#include "ascorr_text/input_name.hpp"

namespace ascorr::host {

const char* describe(StateVerdict v) noexcept {
    switch (v) {
        case StateVerdict::kAccepted:
            return "accepted";
        case StateVerdict::kNotFinite:
            return "position or velocity not finite";
        case StateVerdict::kImplausible:
            return "not a plausible Earth orbit (|r| outside 6478-50000 km or |v| above 12 km/s)";
        case StateVerdict::kTimeBackwards:
            return "time earlier than the previous accepted state's";
        case StateVerdict::kDuplicateTime:
            return "same time as the previous accepted state";
    }
    return "?";
}

namespace {

constexpr std::array<const char*, 7> kNames{"t", "x", "y", "z", "vx", "vy", "vz"};

// The columns of kNames in the header; a missing one is refused.
std::array<std::size_t, 7> state_columns(const Header& header, const std::string& path) {
    std::array<std::size_t, 7> col{};
    for (std::size_t i = 0; i < kNames.size(); ++i) {
        const int c = header.index(kNames[i]);
        if (c < 0) {
            throw text::InputError(path, 1, 1,
                                   std::string("required column '") + kNames[i] + "' is missing from the header");
        }
        col[i] = static_cast<std::size_t>(c);
    }
    return col;
}

struct StateLine {
    const std::string& path;
    std::size_t n;
    std::string_view line;
    const Header& header;
    const std::array<std::size_t, 7>& col;
};

// One data line as a state (InputError naming the field when malformed).
StateRecord parse_state_row(const StateLine& l, std::vector<std::string_view>& fields,
                            std::vector<std::size_t>& starts) {
    const std::string& path = l.path;
    const std::size_t n = l.n;
    const std::string_view line = l.line;
    const Header& header = l.header;
    const std::array<std::size_t, 7>& col = l.col;
    if (const std::size_t bad = split_fields(line, fields, starts); bad != kSplitOk) {
        throw text::InputError(path, n, bad + 1, why_split_failed(line, bad));
    }
    if (fields.size() != header.size()) {
        throw text::InputError(path, n, fields.size() < header.size() ? line.size() + 1 : starts[header.size()] + 1,
                               "expected " + std::to_string(header.size()) + " fields as in the header, found " +
                                   std::to_string(fields.size()) +
                                   (fields.size() < header.size() ? " (truncated row?)" : ""));
    }
    double x[7] = {};
    for (std::size_t i = 0; i < kNames.size(); ++i) {
        const auto v = parse_double(fields[col[i]]);
        if (!v) {
            throw text::InputError(path, n, starts[col[i]] + 1,
                                   std::string("column '") + kNames[i] + "': " + why_not_a_number(fields[col[i]]));
        }
        x[i] = *v;
    }
    TtTime t{};
    if (!tt_from_seconds(x[0], t)) {
        throw text::InputError(
            path, n, starts[col[0]] + 1,
            "column 't': time must be finite and within 1e11 s of J2000, got '" + std::string(fields[col[0]]) + "'");
    }
    return StateRecord{n, t, {x[1], x[2], x[3]}, {x[4], x[5], x[6]}};
}

}  // namespace

StatesFile read_states_file(const std::string& path, StateFrame frame, Diagnostics& diag, bool skip_bad) {
    const std::string text = read_text_file(path);
    LineReader lines(text);
    std::string_view line;
    if (!lines.next(line) || line.empty()) {
        throw text::InputError(path, 1, 1, "empty states file: expected the header t,x,y,z,vx,vy,vz");
    }
    const Header header(line, path);
    const std::array<std::size_t, 7> col = state_columns(header, path);
    StatesFile out;
    out.path = path;
    out.frame = frame;
    // The on-board checks, in file order; its conversions are not used here.
    VelocityService<double> board(default_velocity_service_config());
    std::vector<std::string_view> fields;
    std::vector<std::size_t> starts;
    while (lines.next(line)) {
        if (line.empty()) {
            continue;
        }
        const std::size_t n = lines.line_number();
        try {
            const StateRecord rec = parse_state_row({path, n, line, header, col}, fields, starts);
            const StateVerdict v = board.push_state(rec.t, rec.r_km, rec.v_kms, frame);
            if (v == StateVerdict::kAccepted) {
                out.accepted.push_back(rec);
            } else {
                diag.report("state refused", text::input_name(path) + ":" + std::to_string(n) +
                                                 ": state refused: " + describe(v) + " (kept the previous one)");
            }
        } catch (const text::InputError& e) {
            if (!skip_bad) {
                throw;
            }
            diag.report("malformed states row", std::string(e.what()) + " (--skip-bad: row skipped)");
            ++out.malformed;
        }
    }
    out.counts = board.counts();
    const StateCounts& c = out.counts;
    if (c.accepted + out.refused() + out.malformed == 0U) {
        throw text::InputError(path, lines.line_number() + 1, 1, "the states file has no rows");
    }
    if (c.accepted == 0U) {
        throw text::InputError(
            path, 0, 0,
            "no state of the file is usable: " + std::to_string(out.refused()) + " refused by the velocity service" +
                (out.malformed != 0 ? ", " + std::to_string(out.malformed) + " malformed (--skip-bad)"
                                    : std::string()) +
                "; no row would get a velocity from it (km and km/s in increasing time?)");
    }
    return out;
}

}  // namespace ascorr::host
