// ascorr_host/link/link_transport.hpp: byte transports for the host end of the link.
//
// A Transport moves bytes; framing and retries are LinkClient's. Backends:
//   SerialTransport    a tty (a board on the bench), raw 8N1 via termios;
//   ProcessTransport   a child process's stdin/stdout (QEMU with -serial stdio);
//   LoopbackTransport  the target's LinkServer in this process (tests, and a
//                      reference run of the protocol without hardware);
//   FaultInjector      wraps any of them and corrupts, drops, duplicates or
//                      truncates whole frames in both directions at a rate.
#pragma once

#include <sys/types.h>

#include <cstddef>
#include <cstdint>
#include <deque>
#include <functional>
#include <random>
#include <string>
#include <vector>

namespace ascorr::host {

class Transport {
public:
    virtual ~Transport() = default;
    virtual void write(const std::uint8_t* p, std::size_t n) = 0;
    // Up to cap bytes; waits at most timeout_ms for the first; 0 on time-out.
    virtual std::size_t read(std::uint8_t* p, std::size_t cap, int timeout_ms) = 0;
};

// A serial device, raw mode, 8N1, no flow control.
class SerialTransport final : public Transport {
public:
    SerialTransport(const std::string& device, unsigned baud);
    ~SerialTransport() override;
    void write(const std::uint8_t* p, std::size_t n) override;
    std::size_t read(std::uint8_t* p, std::size_t cap, int timeout_ms) override;

private:
    int fd_ = -1;
    std::string device_;
};

// A child process whose stdin/stdout carry the link (stderr is left alone).
// The child never outlives us: it is killed by the signal cleanup
// (atomic_file.hpp) and, should we be SIGKILLed, by PR_SET_PDEATHSIG (which
// fires when the thread that forked it ends: start it from the main thread).
class ProcessTransport final : public Transport {
public:
    explicit ProcessTransport(const std::vector<std::string>& argv);
    ~ProcessTransport() override;
    void write(const std::uint8_t* p, std::size_t n) override;
    std::size_t read(std::uint8_t* p, std::size_t cap, int timeout_ms) override;
    // Kills the child and starts it again (a target restart).
    void restart();

private:
    void start();
    void stop();
    std::vector<std::string> argv_;
    pid_t pid_ = -1;
    int cleanup_slot_ = -1;
    int to_child_ = -1;
    int from_child_ = -1;
};

// Calls `serve` with each chunk the host writes; `serve` answers by calling
// `reply` with bytes the host will read. Used to run the target's LinkServer
// in process.
class LoopbackTransport final : public Transport {
public:
    using Reply = std::function<void(const std::uint8_t*, std::size_t)>;
    using Serve = std::function<void(const std::uint8_t*, std::size_t, const Reply&)>;
    explicit LoopbackTransport(Serve serve) : serve_(std::move(serve)) {}
    void write(const std::uint8_t* p, std::size_t n) override;
    std::size_t read(std::uint8_t* p, std::size_t cap, int timeout_ms) override;

private:
    Serve serve_;
    std::deque<std::uint8_t> pending_;
};

struct FaultCounts {
    std::size_t corrupted = 0;
    std::size_t dropped = 0;
    std::size_t duplicated = 0;
    std::size_t truncated = 0;
    std::size_t total() const { return corrupted + dropped + duplicated + truncated; }
};

// Injects one fault into a fraction `rate` of whole frames, in both directions;
// the kind (bit flip, drop, duplicate, truncation) is drawn evenly.
class FaultInjector final : public Transport {
public:
    FaultInjector(Transport& inner, double rate, std::uint64_t seed) : inner_(inner), rate_(rate), rng_(seed) {}
    void write(const std::uint8_t* p, std::size_t n) override;
    std::size_t read(std::uint8_t* p, std::size_t cap, int timeout_ms) override;
    const FaultCounts& to_target() const { return to_target_; }
    const FaultCounts& to_host() const { return to_host_; }

private:
    // Applies a fault (or none) to one whole wire frame, delimiter included.
    std::vector<std::uint8_t> mangle(std::vector<std::uint8_t> frame, FaultCounts& counts);
    Transport& inner_;
    double rate_;
    std::mt19937_64 rng_;
    std::vector<std::uint8_t> partial_in_;  // bytes of an incoming frame not yet complete
    std::deque<std::uint8_t> ready_in_;     // incoming bytes after injection
    FaultCounts to_target_;
    FaultCounts to_host_;
};

}  // namespace ascorr::host
