// Writes seed inputs for fuzz_link_server: the bytes the host's LinkClient
// sends in real protocol-v2 to v4 sessions with an in-process LinkServer (model,
// velocity, temperatures, ITRF and GCRS spacecraft states, time-tagged
// solutions with and without the service's velocity, a refused state; the
// estimator's start, commands, model load, report and model; the
// service's horizon; the solutions' calibration use). The
// fuzzer mutates from whole, valid conversations, so it reaches the decoders
// of every message type; tests/fuzz/run writes these seeds afresh each run,
// so they follow the protocol as it changes.
//
// Usage: link_corpus DIR   (writes DIR/v2_*.bin, DIR/v3_*.bin)
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <string>
#include <vector>

#include "ascorr/core/table2.hpp"
#include "ascorr_host/formats/embedded_model.hpp"
#include "ascorr_host/formats/model_csv.hpp"
#include "ascorr_host/link/link_client.hpp"
#include "ascorr_host/link/link_transport.hpp"
#include "ascorr_link/server.hpp"

namespace {

using namespace ascorr;

struct Counter {
    std::uint32_t operator()() const { return 0; }
};

// A LoopbackTransport to a float LinkServer that keeps what the host wrote.
struct Session {
    std::vector<std::uint8_t> sent;
    link::LinkServer<float, Counter> server{7, Counter{}};
    host::LoopbackTransport transport{[this](const std::uint8_t* p, std::size_t n, const auto& reply) {
        sent.insert(sent.end(), p, p + n);
        for (std::size_t i = 0; i < n; ++i) {
            server.on_byte(p[i], reply);
        }
    }};
    host::LinkClient<float> client{transport, 100, 3};
};

// 2025-01-01 00:00 TT in TT microseconds since J2000.0 (2000-01-01 12:00 TT):
// 9131.5 days.
constexpr std::int64_t kT0Us = 788'961'600'000'000;

// A circular-ish LEO state (km, km/s) at TT microseconds t_us.
link::StateUpdate state(std::int64_t t_us, std::uint8_t frame) {
    return link::StateUpdate{TtTime{t_us}, frame, Vector3<double>{6878.0, 0.0, 0.0}, Vector3<double>{0.0, 7.6, 0.0}};
}

void write(const std::string& path, const std::vector<std::uint8_t>& bytes) {
    std::ofstream f(path, std::ios::binary);
    f.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
    if (!f) {
        std::fprintf(stderr, "link_corpus: cannot write %s\n", path.c_str());
        std::exit(1);
    }
}

}  // namespace

int main(int argc, char** argv) {
    if (argc != 2) {
        std::fprintf(stderr, "usage: link_corpus DIR\n");
        return 2;
    }
    const std::string dir = argv[1];
    const ThermalModel<float> model = host::to_core<float>(host::table2_model());
    const Quaternion<float> q{0.5F, 0.5F, 0.5F, 0.5F};
    const HeadTemperatures<float> temps{
        {Celsius<float>{21.0F}, true}, {Celsius<float>{18.5F}, true}, {Celsius<float>{19.0F}, true}};

    // Velocity uploaded by the host, solutions without a time tag.
    {
        Session s;
        s.client.connect();
        s.client.upload_model(model);
        s.client.set_velocity(ObserverVelocity<float>{{1.0e-4F, -2.0e-5F, 3.0e-6F}, 1.0F, true});
        for (std::uint8_t h = 0; h < kMaxHeads; ++h) {
            s.client.set_temperatures(h, temps);
            s.client.correct(h, h, q);
        }
        write(dir + "/v2_uploaded_velocity.bin", s.sent);
    }
    // Velocity from the on-board service: ITRF and GCRS states, a refused
    // one (time backwards), time-tagged solutions before, between and after.
    {
        Session s;
        s.client.connect();
        s.client.upload_model(model);
        s.client.set_service_horizon(3'600'000'000);  // v4: SERVICE_CONFIG before the states
        s.client.set_temperatures(0, temps);
        s.client.correct(1, 0, q, TtTime{kT0Us - 5'000'000}, true, false);
        s.client.send_state(state(kT0Us, 0), true);
        s.client.correct(2, 0, q, TtTime{kT0Us + 1'500'000}, true, true);
        s.client.send_state(state(kT0Us + 10'000'000, 1), true);
        s.client.send_state(state(kT0Us + 2'000'000, 1), false);
        s.client.correct(3, 0, q, TtTime{kT0Us + 60'000'000}, true, true);
        write(dir + "/v2_states.bin", s.sent);
    }
    // Self-calibration (v3): started with Table 2 as version 0, epochs of
    // heads A, B and C, the commands, a model loaded, the report.
    {
        Session s;
        s.client.connect();
        s.client.set_velocity(ObserverVelocity<float>{{1.0e-4F, -2.0e-5F, 3.0e-6F}, 1.0F, true});
        s.client.start_calibration(5'640'000'000, 30.0, &kTable2);
        for (std::uint32_t epoch = 0; epoch < 4; ++epoch) {
            for (std::uint8_t h = 0; h < 3; ++h) {
                s.client.set_temperatures(h, temps);
                // v4: the calibration use (clean; the last epoch's B without a time tag).
                const bool timed = epoch < 3 || h != 1;
                s.client.correct(3 * epoch + h, h, q, TtTime{timed ? kT0Us + epoch * 2'000'000'000LL : 0}, false, false,
                                 timed ? link::kCalibClean : link::kCalibNoTime);
            }
        }
        s.client.calib_command(link::CalibCommand::kFreeze);
        s.client.calib_command(link::CalibCommand::kResume);
        s.client.calib_command(link::CalibCommand::kReset);
        s.client.load_calib_model(kTable2);
        (void)s.client.calib_report();
        (void)s.client.calib_model(0);  // v4: CALIB_MODEL_REQUEST
        write(dir + "/v3_self_calibration.bin", s.sent);
    }
    return 0;
}
