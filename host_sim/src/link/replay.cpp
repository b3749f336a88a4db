#include "ascorr_host/link/replay.hpp"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <memory>
#include <numeric>
#include <optional>
#include <ostream>
#include <stdexcept>
#include <thread>
#include <type_traits>
#include <vector>

#include "ascorr/core/correct.hpp"
#include "ascorr/core/fixed_point.hpp"
#include "ascorr_host/correct/solution_input.hpp"
#include "ascorr_host/formats/atomic_file.hpp"
#include "ascorr_host/formats/corrected_csv.hpp"
#include "ascorr_host/formats/csv.hpp"
#include "ascorr_host/formats/model_csv.hpp"
#include "ascorr_host/formats/states_csv.hpp"
#include "ascorr_host/link/link_client.hpp"
#include "ascorr_host/link/link_transport.hpp"
#include "ascorr_host/link/qemu_targets.hpp"
#include "ascorr_link/server.hpp"

namespace ascorr::host {

namespace {

// Rotation angle between two attitudes, arcsec, from the vector part of a*⊗b.
double angle_arcsec(const Quaternion<double>& a, const Quaternion<double>& b) {
    const Quaternion<double> d = conjugate(a) * b;
    const double s = std::sqrt(d.x * d.x + d.y * d.y + d.z * d.z) / std::sqrt(squared_norm(d));
    return 2.0 * std::asin(std::min(1.0, s)) * kRadToArcsec;
}

template <typename T>
Quaternion<double> widen(const Quaternion<T>& q) {
    const auto d = [](const T& x) { return ScalarTraits<T>::to_double(x); };
    return {d(q.w), d(q.x), d(q.y), d(q.z)};
}

// The in-process target: the firmware's LinkServer behind a loopback.
template <typename T>
class LoopbackTarget {
public:
    struct NoCounter {
        std::uint32_t operator()() const { return 0; }  // no instruction counter in process
    };
    LoopbackTarget()
        : server_(0x4C4F4F50U, NoCounter{}),
          transport_([this](const std::uint8_t* p, std::size_t n, const LoopbackTransport::Reply& reply) {
              for (std::size_t i = 0; i < n; ++i) {
                  server_.on_byte(p[i], reply);
              }
          }) {}
    Transport& transport() { return transport_; }

private:
    link::LinkServer<T, NoCounter> server_;
    LoopbackTransport transport_;
};

template <typename T>
ReplaySummary run(const ReplayOptions& opt, Transport& raw, std::ostream& log) {
    const std::string text = read_text_file(opt.in);
    SolutionsReader reader(opt.in, text);
    refuse_corrected_input(reader);
    const ModelFile mf = read_model_file(opt.model);
    if constexpr (std::is_same_v<T, Q30>) {
        check_fixed_point_range(mf, opt.model);  // refused before the target sees it, as by `correct`
    }
    const ThermalModel<T> model_t = to_core<T>(mf);
    const ThermalModel<double> model_d = to_core<double>(mf);

    std::unique_ptr<FaultInjector> injector;
    Transport* transport = &raw;
    if (opt.inject_errors > 0.0) {
        injector = std::make_unique<FaultInjector>(raw, opt.inject_errors, opt.seed);
        transport = injector.get();
    }
    LinkClient<T> client(*transport, opt.timeout_ms, opt.max_attempts);
    const link::Hello hello = client.connect();
    log << "ascorr replay: target " << opt.target << " (boot id " << hello.boot_id << ", scalar kind "
        << static_cast<int>(hello.scalar_kind) << ")\n";
    client.upload_model(model_t);
    std::optional<StatesFile> states;
    if (!opt.states.empty()) {
        Diagnostics diag(log);
        states = read_states_file(opt.states, opt.states_gcrs ? StateFrame::kGcrs : StateFrame::kItrf, diag);
        diag.summarize();
    }
    // The target's velocity service, mirrored in its scalar and in double.
    VelocityService<T> mirror(default_velocity_service_config());
    VelocityService<double> mirror_d(default_velocity_service_config());
    std::size_t next_state = 0;

    const RowWriter writer(reader);
    AtomicFile out(opt.out);
    out.write(writer.header_line());
    std::string buf;
    ReplaySummary sum;
    EarthVelocity earth;
    SolutionRecord record;
    double instructions = 0.0;
    std::size_t costed = 0;
    const auto start = std::chrono::steady_clock::now();
    double t0 = 0.0;
    std::uint32_t id = 0;
    constexpr int kMaxVelocityMessages = 20;  // as the diagnostics of `ascorr correct`
    int velocity_messages = 0;
    // The rows go to the target in time order, as a DPU takes them (its
    // velocity service is causal: a row earlier than a state it already has
    // would get none), so that any row order gives `ascorr correct`'s answers;
    // they are written in file order.
    std::vector<SolutionRecord> rows;
    while (reader.next(record)) {
        rows.push_back(record);
    }
    const auto key = [&](std::size_t i) { return std::isnan(rows[i].t) ? HUGE_VAL : rows[i].t; };
    std::vector<std::size_t> order(rows.size());
    std::iota(order.begin(), order.end(), std::size_t{0});
    std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return key(a) < key(b); });
    struct Written {
        std::optional<Quaternion<double>> q;  // none: rejected, the input text unchanged
        StatusBits status;
    };
    std::vector<Written> written_rows(rows.size());
    for (const std::size_t k : order) {
        const SolutionRecord& rec = rows[k];
        if (opt.realtime) {
            if (id == 0) {
                t0 = rec.t;
            }
            std::this_thread::sleep_until(start + std::chrono::duration<double>(rec.t - t0));
        }
        SolutionInput<T> in = to_core_input<T>(rec, &earth);
        SolutionInput<double> in_d = to_core_input<double>(rec, &earth);
        TtTime t{};
        const bool wants_states = states && rec.velocity_components == 0;
        const bool from_states = wants_states && tt_from_seconds(rec.t, t);
        // A time the on-board clock cannot hold (|t| > 1e11 s): the states
        // cannot give a velocity, 4|32 as in `ascorr correct --states`.
        const bool time_unusable = wants_states && !from_states;
        StatusBits service_status = 0U;
        StatusBits service_status_d = 0U;
        if (from_states) {
            const auto& a = states->accepted;
            for (; next_state < a.size() && a[next_state].t <= t; ++next_state) {  // the bus's time order
                const StateRecord& s = a[next_state];
                const StateFrame frame = states->frame;
                client.send_state(
                    {s.t, static_cast<std::uint8_t>(frame == StateFrame::kGcrs ? 1U : 0U), s.r_km, s.v_kms}, true);
                mirror.push_state(s.t, s.r_km, s.v_kms, frame);
                mirror_d.push_state(s.t, s.r_km, s.v_kms, frame);
            }
            mirror.advance(t, OnBoardEarth{});
            mirror_d.advance(t, OnBoardEarth{});
            const ServiceVelocity<T> v = mirror.velocity_at(t);
            const ServiceVelocity<double> vd = mirror_d.velocity_at(t);
            in.velocity = v.velocity;
            in_d.velocity = vd.velocity;
            service_status = v.status;
            service_status_d = vd.status;
        } else {
            client.set_velocity(in.velocity);
        }
        client.set_temperatures(in.head, in.temperatures);
        ++sum.frames;
        const link::SolutionOut<T> got =
            client.correct(id, in.head, in.q_chu_icrf, t, from_states, from_states && in.velocity.valid);
        ++sum.returned;
        CorrectedSolution<T> host = correct_solution(in, CorrectionConfig<T>{true, &model_t});
        host.status = with_service_status(host.status, service_status, from_states);
        CorrectedSolution<double> ref = correct_solution(in_d, CorrectionConfig<double>{true, &model_d});
        ref.status = with_service_status(ref.status, service_status_d, from_states);
        const bool same =
            got.status == host.status && std::memcmp(&got.q_chu_icrf, &host.q_chu_icrf, sizeof host.q_chu_icrf) == 0;
        if (!same) {
            ++sum.mismatches;
            if (sum.mismatches <= 20) {
                log << opt.in << ":" << rec.line << ": the target's answer differs from the host core (status "
                    << got.status << " vs " << host.status << ")\n";
            }
        }
        if ((got.status & status::kRejected) == 0U && (ref.status & status::kRejected) == 0U) {
            sum.max_error_arcsec = std::max(sum.max_error_arcsec, angle_arcsec(widen(got.q_chu_icrf), ref.q_chu_icrf));
        }
        if ((got.status & (status::kAberrationApplied | status::kThermalApplied)) ==
            (status::kAberrationApplied | status::kThermalApplied)) {
            instructions += got.instructions;
            ++costed;
        }
        // The bits the host adds (velocity given but unusable before the core
        // sees it), as `ascorr correct` does.
        StatusBits written = host_status(rec, true, got.status);
        if (time_unusable && (written & status::kNoVelocity) != 0U) {
            written = static_cast<StatusBits>(written | status::kVelocityInvalid);
        }
        if (written != got.status && velocity_messages < kMaxVelocityMessages) {
            ++velocity_messages;
            log << opt.in << ":" << rec.line << ": "
                << (time_unusable ? "t is outside the on-board clock's range: no velocity from the states"
                                  : velocity_problem(rec))
                << ": aberration skipped\n";
        }
        written_rows[k] = {(got.status & status::kRejected) != 0U ? std::nullopt : std::optional(widen(got.q_chu_icrf)),
                           written};
        ++id;
    }
    SolutionsReader again(opt.in, text);
    for (std::size_t k = 0; again.next(record); ++k) {
        writer.row(again, written_rows[k].q, written_rows[k].status, buf);
    }
    out.write(buf);
    out.commit();
    const LinkStats& st = client.stats();
    sum.crc_errors = st.naks + st.broken_answers;
    sum.retries = st.retries;
    sum.restarts = st.restarts;
    sum.instructions_per_solution = costed == 0 ? 0.0 : instructions / static_cast<double>(costed);
    if (injector) {
        sum.injected = injector->to_target().total() + injector->to_host().total();
    }
    return sum;
}

}  // namespace

namespace {

// Refuses, naming the file and why, an image QEMU would fail on only after
// starting (a register dump, then a closed link): not a 32-bit little-endian
// ARM executable ELF, a hard-float image for a board without an FPU (the
// toolchain's cpus with an FPU are named so: cortex-m4f), or an entry point outside the MPS2
// boards' code memory, where the images are linked (__flash = 0, 4 MiB:
// toolchain/arm-none-eabi-picolibc.cmake).
void check_link_image(const std::string& path, const QemuTarget& board) {
    constexpr std::uint32_t kCodeMemoryBytes = 0x400000U;
    constexpr std::uint16_t kElfExecutable = 2U;
    constexpr std::uint16_t kElfMachineArm = 40U;
    constexpr std::uint32_t kArmFloatHard = 0x400U;  // EF_ARM_ABI_FLOAT_HARD
    std::ifstream f(path, std::ios::binary);
    unsigned char h[52] = {};
    f.read(reinterpret_cast<char*>(h), sizeof h);
    const auto u16 = [&](std::size_t at) { return static_cast<std::uint16_t>(h[at] | (h[at + 1] << 8)); };
    const auto u32 = [&](std::size_t at) {
        return static_cast<std::uint32_t>(h[at]) | (static_cast<std::uint32_t>(h[at + 1]) << 8) |
               (static_cast<std::uint32_t>(h[at + 2]) << 16) | (static_cast<std::uint32_t>(h[at + 3]) << 24);
    };
    const std::string where = "--firmware " + path + ": not a link image for --target " + std::string(board.replay) +
                              " (" + std::string(board.machine) + "): ";
    if (f.gcount() < static_cast<std::streamsize>(sizeof h) || h[0] != 0x7F || h[1] != 'E' || h[2] != 'L' ||
        h[3] != 'F') {
        throw std::runtime_error(where + "not an ELF file");
    }
    if (h[4] != 1 || h[5] != 1) {
        throw std::runtime_error(where + "not a 32-bit little-endian ELF (class " + std::to_string(h[4]) + ", data " +
                                 std::to_string(h[5]) + ")");
    }
    if (u16(18) != kElfMachineArm) {
        throw std::runtime_error(where + "ELF machine " + std::to_string(u16(18)) + ", not ARM (40)");
    }
    if (u16(16) != kElfExecutable) {
        throw std::runtime_error(where + "ELF type " + std::to_string(u16(16)) + ", not an executable (2)");
    }
    const bool hard = (u32(36) & kArmFloatHard) != 0U;
    const bool fpu = !board.cpu.empty() && board.cpu.back() == 'f';
    if (hard && !fpu) {
        throw std::runtime_error(where + "a hard-float image, and the board's cpu (" + std::string(board.cpu) +
                                 ") has no FPU");
    }
    const std::uint32_t entry = u32(24);
    if (entry >= kCodeMemoryBytes) {
        char buf[120];
        std::snprintf(buf, sizeof buf, "entry point 0x%08x is outside the board's code memory [0, 0x%x)", entry,
                      kCodeMemoryBytes);
        throw std::runtime_error(where + buf);
    }
}

}  // namespace

ReplaySummary replay(const ReplayOptions& opt, std::ostream& log) {
    refuse_output_over_input(
        {{"--in", opt.in}, {"--model", opt.model}, {"--firmware", opt.firmware}, {"--states", opt.states}},
        {{"--out", opt.out}}, true);
    if (std::llround(opt.max_propagation_s * 1e6) != default_velocity_service_config().horizon_us) {
        char buf[256];
        std::snprintf(buf, sizeof buf,
                      "--max-propagation %.17g: a target propagates a state for %.17g s, the "
                      "horizon built into its firmware; replay cannot change it (correct can)",
                      opt.max_propagation_s, static_cast<double>(default_velocity_service_config().horizon_us) * 1e-6);
        throw std::runtime_error(buf);
    }
    ReplayOptions o = opt;
    if (opt.target == "loopback-float") {
        o.timeout_ms = opt.timeout_ms > 0 ? opt.timeout_ms : 1;  // answers are there at once or never
        LoopbackTarget<float> target;
        return run<float>(o, target.transport(), log);
    }
    if (const QemuTarget* board = find_qemu_target(opt.target)) {  // toolchain/targets.txt
        const bool fixed = board->scalar == ScalarKind::kFixed;
        // QEMU answers within a few milliseconds; a lost frame is resent soon after
        // (a late answer only costs a resend, answered from the cache).
        // With states the target's double propagation and Earth series (software
        // double on both boards) can delay an answer past 20 ms on a loaded machine.
        o.timeout_ms = opt.timeout_ms > 0 ? opt.timeout_ms : (opt.states.empty() ? 20 : 100);
        const std::string image = opt.firmware.empty() ? default_link_firmware(std::string(board->cpu)) : opt.firmware;
        if (!std::ifstream(image).good()) {
            throw std::runtime_error(image + ": cannot read the link firmware image");
        }
        check_link_image(image, *board);
        ProcessTransport qemu(qemu_link_command(std::string(board->machine), image));
        return fixed ? run<Q30>(o, qemu, log) : run<float>(o, qemu, log);
    }
    if (opt.target.rfind("/dev/", 0) == 0) {
        o.timeout_ms = opt.timeout_ms > 0 ? opt.timeout_ms : 500;
        SerialTransport serial(opt.target, opt.baud);
        // The target says in its HELLO which core it runs (float or Q30); the
        // session then speaks that scalar.
        const std::uint8_t kind = LinkClient<float>(serial, o.timeout_ms, o.max_attempts).request_hello().scalar_kind;
        if (kind == link::WireTraits<Q30>::kKind) {
            return run<Q30>(o, serial, log);
        }
        if (kind == link::WireTraits<float>::kKind) {
            return run<float>(o, serial, log);
        }
        throw LinkError(opt.target + ": the target computes in scalar kind " + std::to_string(kind) +
                        ", which this host does not speak (1 = float, 2 = Q30)");
    }
    throw std::runtime_error("--target " + opt.target + ": unknown target (loopback-float, " + qemu_target_names() +
                             " or a serial device such as /dev/ttyUSB0)");
}

std::vector<std::string> qemu_link_command(const std::string& machine, const std::string& image) {
    // UART0 on our stdin/stdout (no monitor, no mux, no signals from bytes
    // like 0x03); semihosting, unused by the link image, to a null device;
    // -icount shift=0: one instruction per nanosecond while the core runs, so
    // that the image's SysTick counts instructions (40 per count,
    // firmware/app/link_main.cpp); sleep=off keeps virtual time out of real
    // time (the image stops SysTick while it waits, so QEMU idles, with a
    // one-line warning that no timer is active).
    return {"qemu-system-arm",
            "-M",
            machine,
            "-display",
            "none",
            "-monitor",
            "none",
            "-chardev",
            "stdio,id=link,signal=off",
            "-serial",
            "chardev:link",
            "-chardev",
            "null,id=semi",
            "-semihosting-config",
            "enable=on,target=native,chardev=semi",
            "-icount",
            "shift=0,sleep=off",
            "-kernel",
            image};
}

std::string default_link_firmware(const std::string& target) {
#ifdef ASCORR_LINK_FIRMWARE_DIR
    const std::string path =
        std::string(ASCORR_LINK_FIRMWARE_DIR) + "/" + target + "/firmware/app/ascorr_link_firmware.elf";
    if (std::ifstream(path).good()) {
        return path;
    }
    throw std::runtime_error(path +
                             ": no link firmware image; build with the ci preset (ASCORR_TARGETS) or pass --firmware");
#else
    throw std::runtime_error("no link firmware image for " + target +
                             " in this build (configured without ASCORR_TARGETS): pass --firmware");
#endif
}

std::string to_json(const ReplaySummary& s) {
    char buf[512];
    std::snprintf(buf, sizeof buf,
                  "{\"frames\": %zu, \"returned\": %zu, \"mismatches\": %zu, \"max_error_arcsec\": %.6g, "
                  "\"crc_errors\": %zu, \"retries\": %zu, \"instructions_per_solution\": %.1f, \"restarts\": %zu, "
                  "\"injected_faults\": %zu}",
                  s.frames, s.returned, s.mismatches, s.max_error_arcsec, s.crc_errors, s.retries,
                  s.instructions_per_solution, s.restarts, s.injected);
    return buf;
}

}  // namespace ascorr::host
