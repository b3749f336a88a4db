// `ascorr replay --states`: states and solutions go to the target in time
// order, the target computes the velocity (link protocol v2), and every answer
// is compared bit for bit with the host's mirror of the target's service in the
// target's scalar. In process (loopback, float) the replayed file must equal
// `ascorr correct --states --scalar float` byte for byte; under QEMU (label
// target) both boards, clean and with 1 % faulted frames, and a restart.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <fstream>
#include <ostream>
#include <sstream>
#include <string>
#include <string_view>
#include <type_traits>
#include <vector>

#include "ascorr/core/fixed_point.hpp"
#include "ascorr/nav/velocity_service.hpp"
#include "ascorr_host/correct/earth_velocity.hpp"
#include "ascorr_host/correct/solution_input.hpp"
#include "ascorr_host/formats/model_csv.hpp"
#include "ascorr_host/formats/states_csv.hpp"
#include "ascorr_host/link/link_client.hpp"
#include "ascorr_host/link/link_transport.hpp"
#include "ascorr_host/link/qemu_targets.hpp"
#include "ascorr_host/link/replay.hpp"
#include "cli_run.hpp"
#include "replay_boards.hpp"
#include "states_recording.hpp"
#include "test_support.hpp"

namespace ascorr::test {
namespace {

host::ReplaySummary replay_states(const std::string& target, double inject, int rows, const std::string& name,
                                  StatesRecording* rec_out = nullptr) {
    const auto dir = scratch_dir(name);
    const StatesRecording rec = make_states_recording(dir, rows);
    host::ReplayOptions o;
    o.target = target;
    o.in = rec.solutions;
    o.states = rec.states;
    o.model = data_path("model_table2.csv");
    o.out = (dir / "out.csv").string();
    o.inject_errors = inject;
    o.seed = 3;
    std::ostringstream log;
    const host::ReplaySummary s = host::replay(o, log);
    std::cout << target << " --states, inject " << inject << ": " << host::to_json(s) << "\n";
    if (rec_out != nullptr) {
        *rec_out = rec;
    }
    return s;
}

// `ascorr correct --scalar float --states` (and `extra`) of the recording into
// dir/correct.csv: the replayed dir/out.csv, set in `replayed`, equals it.
void expect_replayed_as_correct(const StatesRecording& rec, const std::filesystem::path& dir, const std::string& extra,
                                std::string& replayed) {
    const std::string cmd = std::string(ASCORR_EXE) + " correct --scalar float --in " + rec.solutions + " --out " +
                            (dir / "correct.csv").string() + " --model " + data_path("model_table2.csv") +
                            " --states " + rec.states + extra + " 2>/dev/null";
    ASSERT_EQ(std::system(cmd.c_str()), 0);
    replayed = slurp((dir / "out.csv").string());
    EXPECT_EQ(replayed, slurp((dir / "correct.csv").string()));
}

TEST(ReplayStates, LoopbackEqualsCorrectWithStates) {
    StatesRecording rec;
    const host::ReplaySummary s = replay_states("loopback-float", 0.0, 900, "replay_states_loop", &rec);
    EXPECT_EQ(s.returned, 900U);
    EXPECT_EQ(s.mismatches, 0U);
    EXPECT_LE(s.max_error_arcsec, 0.05);
    const std::filesystem::path dir = std::filesystem::path(rec.solutions).parent_path();
    std::string replayed;
    ASSERT_NO_FATAL_FAILURE(expect_replayed_as_correct(rec, dir, "", replayed));
    // Before the first state: status 4 (+ thermal); in and after the 40 s gap: applied.
    EXPECT_NE(replayed.find(",6\n"), std::string::npos);  // 4 | 2
    EXPECT_NE(replayed.find(",3\n"), std::string::npos);  // 1 | 2
}

// --max-propagation goes to the target (SERVICE_CONFIG): with a 10 s horizon
// the rows in the recording's 40 s gap more than 10 s after the last state
// are stale on the target (4|512, thermal applied: 518), as by `ascorr
// correct --states --max-propagation 10`, byte for byte; with the default
// horizon none is (the control).
TEST(ReplayStates, LoopbackMaxPropagationEqualsCorrect) {
    const auto dir = scratch_dir("replay_states_horizon");
    const StatesRecording rec = make_states_recording(dir, 1000);  // epochs to 98 s: through the gap
    host::ReplayOptions o;
    o.target = "loopback-float";
    o.in = rec.solutions;
    o.states = rec.states;
    o.model = data_path("model_table2.csv");
    o.out = (dir / "default.csv").string();
    std::ostringstream log;
    EXPECT_EQ(host::replay(o, log).mismatches, 0U) << log.str();
    EXPECT_EQ(slurp((dir / "default.csv").string()).find(",518\n"), std::string::npos);
    o.max_propagation_s = 10.0;
    o.out = (dir / "out.csv").string();
    const host::ReplaySummary s = host::replay(o, log);
    EXPECT_EQ(s.returned, 1000U);
    EXPECT_EQ(s.mismatches, 0U) << log.str();
    std::string replayed;
    ASSERT_NO_FATAL_FAILURE(expect_replayed_as_correct(rec, dir, " --max-propagation 10", replayed));
    EXPECT_NE(replayed.find(",518\n"), std::string::npos);
}

// Rows out of time order: replay sends them to the target in time order (the
// service is causal) and writes them in file order, so the replayed file still
// equals `ascorr correct --states` of the same rows (before, a row earlier than
// a state already sent got no velocity: status 4).
TEST(ReplayStates, LoopbackReversedRowsEqualCorrectWithStates) {
    const auto dir = scratch_dir("replay_states_reversed");
    const StatesRecording rec = make_states_recording(dir, 600);
    std::ifstream f(rec.solutions);
    std::string header;
    std::getline(f, header);
    std::vector<std::string> lines;
    for (std::string l; std::getline(f, l);) {
        lines.push_back(l);
    }
    const std::string reversed = (dir / "reversed.csv").string();
    {
        std::ofstream o(reversed);
        o << header << '\n';
        for (auto it = lines.rbegin(); it != lines.rend(); ++it) {
            o << *it << '\n';
        }
    }
    host::ReplayOptions o;
    o.target = "loopback-float";
    o.in = reversed;
    o.states = rec.states;
    o.model = data_path("model_table2.csv");
    o.out = (dir / "out.csv").string();
    std::ostringstream log;
    const host::ReplaySummary s = host::replay(o, log);
    EXPECT_EQ(s.returned, 600U);
    EXPECT_EQ(s.mismatches, 0U) << log.str();
    const std::string cmd = std::string(ASCORR_EXE) + " correct --scalar float --in " + reversed + " --out " +
                            (dir / "correct.csv").string() + " --model " + data_path("model_table2.csv") +
                            " --states " + rec.states + " 2>/dev/null";
    ASSERT_EQ(std::system(cmd.c_str()), 0);
    const std::string replayed = slurp((dir / "out.csv").string());
    const std::string corrected = slurp((dir / "correct.csv").string());
    const auto diff = std::mismatch(replayed.begin(), replayed.end(), corrected.begin(), corrected.end());
    EXPECT_TRUE(replayed == corrected) << "first difference at byte " << (diff.first - replayed.begin()) << ": "
                                       << replayed.substr(static_cast<std::size_t>(diff.first - replayed.begin()), 80);
    EXPECT_NE(replayed.find(",3\n"), std::string::npos);  // velocities from the states applied
}

#ifdef ASCORR_REPLAY_QEMU
constexpr int kRows = 1000;

void expect_complete(const host::ReplaySummary& s, double bound) {
    EXPECT_EQ(s.frames, static_cast<std::size_t>(kRows));
    EXPECT_EQ(s.returned, static_cast<std::size_t>(kRows));
    EXPECT_EQ(s.mismatches, 0U);
    EXPECT_LE(s.max_error_arcsec, bound);
    EXPECT_EQ(s.restarts, 0U);
}

// Every board of toolchain/targets.txt (the generated kQemuTargets), each at
// the bound of its scalar (tests/target/accuracy-bounds.txt, compile
// definitions of tests/CMakeLists.txt).
double bound_arcsec(const host::QemuTarget& board) {
    return board.scalar == host::ScalarKind::kFixed ? ASCORR_BOUND_FIXED_ARCSEC : ASCORR_BOUND_FLOAT_ARCSEC;
}

std::string scratch_name(const host::QemuTarget& board, const std::string& what) {
    return "rs_" + board_name(board) + what;
}

class ReplayStatesQemu : public ::testing::TestWithParam<host::QemuTarget> {};

TEST_P(ReplayStatesQemu, Clean) {
    expect_complete(replay_states(std::string(GetParam().replay), 0.0, kRows, scratch_name(GetParam(), "")),
                    bound_arcsec(GetParam()));
}
TEST_P(ReplayStatesQemu, OnePercentFaults) {
    const host::ReplaySummary s =
        replay_states(std::string(GetParam().replay), 0.01, kRows, scratch_name(GetParam(), "_f"));
    expect_complete(s, bound_arcsec(GetParam()));
    EXPECT_GT(s.crc_errors, 0U);
}

// The emulator killed halfway: the client restores the model, temperatures
// and the latest accepted state, and every answer stays exact.
template <typename T>
void survive_restart(const host::QemuTarget* board, const std::string& name) {
    ASSERT_EQ(board->scalar, (std::is_same_v<T, Q30> ? host::ScalarKind::kFixed : host::ScalarKind::kFloat));
    constexpr int kRestartRows = 600;
    const auto dir = scratch_dir(name);
    const StatesRecording rec = make_states_recording(dir, kRestartRows);
    std::ostringstream log;
    host::Diagnostics diag(log);
    const host::StatesFile states = host::read_states_file(rec.states, StateFrame::kItrf, diag);
    const std::string text = host::read_text_file(rec.solutions);
    host::SolutionsReader reader(rec.solutions, text);
    const ThermalModel<T> model = host::to_core<T>(host::read_model_file(data_path("model_table2.csv")));
    host::ProcessTransport qemu(
        host::qemu_link_command(std::string(board->machine), host::default_link_firmware(std::string(board->cpu))));
    host::LinkClient<T> client(qemu, 50, 20);
    client.connect();
    client.upload_model(model);
    VelocityService<T> mirror(default_velocity_service_config());
    host::EarthVelocity earth;
    host::SolutionRecord r;
    std::uint32_t id = 0;
    std::size_t next = 0;
    std::size_t from_states_applied = 0;
    while (reader.next(r)) {
        if (id == kRestartRows / 2) {
            qemu.restart();
        }
        SolutionInput<T> in = host::to_core_input<T>(r, &earth);
        TtTime t{};
        ASSERT_TRUE(tt_from_seconds(r.t, t));
        const bool from_states = r.velocity_components == 0;
        StatusBits sv = 0U;
        if (from_states) {
            for (; next < states.accepted.size() && states.accepted[next].t <= t; ++next) {
                const host::StateRecord& s = states.accepted[next];
                client.send_state({s.t, 0U, s.r_km, s.v_kms}, true);
                mirror.push_state(s.t, s.r_km, s.v_kms, StateFrame::kItrf);
            }
            mirror.advance(t, OnBoardEarth{});
            const ServiceVelocity<T> v = mirror.velocity_at(t);
            in.velocity = v.velocity;
            sv = v.status;
        } else {
            client.set_velocity(in.velocity);
        }
        client.set_temperatures(in.head, in.temperatures);
        const link::SolutionOut<T> got =
            client.correct(id, in.head, in.q_chu_icrf, t, from_states, from_states && in.velocity.valid);
        CorrectedSolution<T> want = correct_solution(in, CorrectionConfig<T>{true, &model});
        want.status = with_service_status(want.status, sv, from_states);
        ASSERT_EQ(got.status, want.status) << "row " << id;
        ASSERT_EQ(std::memcmp(&got.q_chu_icrf, &want.q_chu_icrf, sizeof want.q_chu_icrf), 0) << "row " << id;
        from_states_applied += from_states && id > kRestartRows / 2 && (got.status & 1U) != 0U ? 1U : 0U;
        ++id;
    }
    EXPECT_EQ(client.stats().restarts, 1U);
    EXPECT_GT(from_states_applied, static_cast<std::size_t>(kRestartRows / 3));  // the state was restored
}

TEST_P(ReplayStatesQemu, RestartRestoresTheState) {
    with_board_scalar(GetParam(), [this](auto scalar) {
        survive_restart<decltype(scalar)>(&GetParam(), scratch_name(GetParam(), "_restart"));
    });
}

// Each test once per board: Boards/ReplayStatesQemu.Clean/qemu_m3, ...
INSTANTIATE_TEST_SUITE_P(Boards, ReplayStatesQemu, ::testing::ValuesIn(host::kQemuTargets), board_test_name);
#endif

}  // namespace
}  // namespace ascorr::test
