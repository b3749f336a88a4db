// `ascorr replay`: the options' checks, the targets (loopback, QEMU and its images, serial) and the entry points.
#include "ascorr_host/link/replay.hpp"

#include <cstdint>
#include <fstream>
#include <ostream>
#include <stdexcept>
#include <string>
#include <vector>

#include "ascorr_host/correct/self_calibration.hpp"
#include "ascorr_host/correct/states_velocity.hpp"
#include "ascorr_host/formats/atomic_file.hpp"
#include "ascorr_host/formats/csv.hpp"
#include "ascorr_host/formats/model_csv.hpp"
#include "ascorr_host/link/link_client.hpp"
#include "ascorr_host/link/link_transport.hpp"
#include "ascorr_host/link/qemu_targets.hpp"
#include "ascorr_link/server.hpp"
#include "ascorr_text/c_format.hpp"
#include "replay_parts.hpp"

namespace ascorr::host {

namespace {

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
        text::c_snprintf(buf, sizeof buf, "entry point 0x%08x is outside the board's code memory [0, 0x%x)", entry,
                         kCodeMemoryBytes);
        throw std::runtime_error(where + buf);
    }
}

// --self-calibrate's options, or without it the model the target corrects with.
void check_calibration_options(const ReplayOptions& opt) {
    if (opt.self_calibrate) {
        if (!opt.states.empty()) {  // as `ascorr correct --self-calibrate`
            throw std::runtime_error(
                "--self-calibrate learns from rows with their own vx,vy,vz: it cannot go with --states");
        }
        if (!opt.model_history.empty()) {
            refuse_same_output({"--out", opt.out}, {"--model-history", opt.model_history});
        }
        if (!calib::time_constant_acceptable(opt.time_constant_days)) {
            throw std::runtime_error("--time-constant " + number_text(opt.time_constant_days) + ": must be in " +
                                     time_constant_range() + " days");
        }
        if (opt.orbit_period_s && !orbit_period_acceptable(*opt.orbit_period_s)) {
            throw std::runtime_error("--orbit-period " + number_text(*opt.orbit_period_s) + ": must be in " +
                                     orbit_period_range() + " s");
        }
    } else {
        if (opt.model.empty()) {
            throw std::runtime_error(
                "--model is needed (the thermal model the target corrects with), unless "
                "--self-calibrate");
        }
        if (!opt.model_history.empty()) {
            throw std::runtime_error("--model-history needs --self-calibrate");
        }
        if (opt.orbit_period_s) {
            throw std::runtime_error("--orbit-period needs --self-calibrate");
        }
        if (opt.lag_s) {
            throw std::runtime_error(std::string("--lag ") + kLagNeedsSelfCalibration);
        }
        if (opt.sun_auto) {
            throw std::runtime_error(std::string("--sun-term ") + kSunTermNeedsSelfCalibration);
        }
    }
    if (const std::string bad = bad_lag_text(opt.lag_s); !bad.empty()) {
        throw std::runtime_error(bad);
    }
}

// The options' refusals that need no input read (nothing was written).
void check_options(const ReplayOptions& opt) {
    std::vector<NamedPath> outputs = {{"--out", opt.out}};
    if (!opt.model_history.empty()) {
        outputs.push_back({"--model-history", opt.model_history});
    }
    if (!opt.combined.empty()) {
        outputs.push_back({"--combined", opt.combined});
    }
    refuse_output_over_input({{"--in", opt.in},
                              {"--model", opt.model},
                              {"--firmware", opt.firmware},
                              {"--states", opt.states},
                              {"--mountings", opt.mountings}},
                             outputs, true);
    if (opt.combined.empty() != opt.mountings.empty()) {
        throw std::runtime_error("--mountings and --combined go together");
    }
    if (!opt.combined.empty()) {
        refuse_same_output({"--out", opt.out}, {"--combined", opt.combined});
        if (!opt.model_history.empty()) {
            refuse_same_output({"--model-history", opt.model_history}, {"--combined", opt.combined});
        }
    }
    if (opt.max_propagation_s && !max_propagation_acceptable(*opt.max_propagation_s)) {
        throw std::runtime_error("--max-propagation " + number_text(*opt.max_propagation_s) + ": " +
                                 kMaxPropagationRule);
    }
    check_calibration_options(opt);
}

// The session over a transport already open: the target's HELLO says which
// scalar it computes in, and the session speaks that one.
ReplaySummary run_as_announced(const ReplayOptions& o, Transport& transport, OutputSet& outputs, std::ostream& log) {
    const std::uint8_t kind = LinkClient<float>(transport, o.timeout_ms, o.max_attempts).request_hello().scalar_kind;
    if (kind == link::WireTraits<Q30>::kKind) {
        return detail::run<Q30>(o, transport, outputs, log);
    }
    if (kind == link::WireTraits<float>::kKind) {
        return detail::run<float>(o, transport, outputs, log);
    }
    throw LinkError(o.target + ": the target computes in scalar kind " + std::to_string(kind) +
                    ", which this host does not speak (1 = float, 2 = Q30)");
}

}  // namespace

std::vector<NamedPath> replay_inputs(const ReplayOptions& opt) {
    return {{"--in", opt.in},
            {"--model", opt.model},
            {"--firmware", opt.firmware},
            {"--states", opt.states},
            {"--mountings", opt.mountings}};
}

std::vector<NamedPath> replay_outputs(const ReplayOptions& opt) {
    std::vector<NamedPath> outputs = {{"--out", opt.out}};
    if (opt.self_calibrate && !opt.model_history.empty()) {
        outputs.push_back({"--model-history", opt.model_history});
    }
    if (!opt.combined.empty()) {
        outputs.push_back({"--combined", opt.combined});
    }
    return outputs;
}

ReplaySummary replay_over(const ReplayOptions& opt, Transport& transport, std::ostream& log) {
    check_options(opt);
    OutputSet outputs(replay_outputs(opt), replay_inputs(opt));
    ReplayOptions o = opt;
    o.timeout_ms = opt.timeout_ms > 0 ? opt.timeout_ms : 500;
    const ReplaySummary s = run_as_announced(o, transport, outputs, log);
    outputs.commit();
    return s;
}

ReplaySummary replay(const ReplayOptions& opt, std::ostream& log) {
    check_options(opt);
    OutputSet outputs(replay_outputs(opt), replay_inputs(opt));
    const ReplaySummary s = replay(opt, outputs, log);
    outputs.commit();
    return s;
}

ReplaySummary replay(const ReplayOptions& opt, OutputSet& outputs, std::ostream& log) {
    check_options(opt);
    ReplayOptions o = opt;
    if (opt.target == kLoopbackFloat || opt.target == kLoopbackFixed) {
        o.timeout_ms = opt.timeout_ms > 0 ? opt.timeout_ms : 1;  // answers are there at once or never
        if (opt.target == kLoopbackFixed) {
            LoopbackTarget<Q30> target;
            return detail::run<Q30>(o, target.transport(), outputs, log);
        }
        LoopbackTarget<float> target;
        return detail::run<float>(o, target.transport(), outputs, log);
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
        return fixed ? detail::run<Q30>(o, qemu, outputs, log) : detail::run<float>(o, qemu, outputs, log);
    }
    if (opt.target.rfind("/dev/", 0) == 0) {
        o.timeout_ms = opt.timeout_ms > 0 ? opt.timeout_ms : 500;
        SerialTransport serial(opt.target, opt.baud);
        return run_as_announced(o, serial, outputs, log);
    }
    throw std::runtime_error("--target " + opt.target + ": unknown target (" + kLoopbackFloat + ", " + kLoopbackFixed +
                             ", " + qemu_target_names() + " or a serial device such as /dev/ttyUSB0)");
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

}  // namespace ascorr::host
