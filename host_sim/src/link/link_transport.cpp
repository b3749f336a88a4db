#include "ascorr_host/link/link_transport.hpp"

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <termios.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstring>
#include <stdexcept>

#include "ascorr_host/formats/atomic_file.hpp"
#include "ascorr_text/c_format.hpp"

namespace ascorr::host {

namespace {
[[noreturn]] void sys_error(const std::string& what) {
    throw std::runtime_error(what + ": " + std::strerror(errno));
}

void write_all(int fd, const std::uint8_t* p, std::size_t n, const std::string& what) {
    while (n > 0) {
        const ssize_t w = ::write(fd, p, n);
        if (w < 0) {
            if (errno == EINTR) {
                continue;
            }
            sys_error(what);
        }
        p += w;
        n -= static_cast<std::size_t>(w);
    }
}

std::size_t read_some(int fd, std::uint8_t* p, std::size_t cap, int timeout_ms, const std::string& what) {
    pollfd pfd{fd, POLLIN, 0};
    for (;;) {
        const int r = ::poll(&pfd, 1, timeout_ms);
        if (r < 0 && errno == EINTR) {
            continue;
        }
        if (r < 0) {
            sys_error(what);
        }
        if (r == 0) {
            return 0;
        }
        const ssize_t n = ::read(fd, p, cap);
        if (n < 0 && errno == EINTR) {
            continue;
        }
        if (n < 0) {
            sys_error(what);
        }
        if (n == 0) {
            throw std::runtime_error(what + ": the other end closed the link");
        }
        return static_cast<std::size_t>(n);
    }
}

speed_t baud_constant(unsigned baud) {
    switch (baud) {
        case 9600:
            return B9600;
        case 19200:
            return B19200;
        case 38400:
            return B38400;
        case 57600:
            return B57600;
        case 115200:
            return B115200;
        case 230400:
            return B230400;
        case 460800:
            return B460800;
        case 921600:
            return B921600;
        default:
            throw std::runtime_error("unsupported baud rate " + std::to_string(baud));
    }
}
}  // namespace

SerialTransport::SerialTransport(const std::string& device, unsigned baud) : device_(device) {
    fd_ = ::open(device.c_str(), O_RDWR | O_NOCTTY | O_CLOEXEC);
    if (fd_ < 0) {
        sys_error(device);
    }
    termios tio{};
    if (::tcgetattr(fd_, &tio) != 0) {
        const int e = errno;
        ::close(fd_);
        errno = e;
        sys_error(device + ": not a serial device");
    }
    ::cfmakeraw(&tio);
    tio.c_cflag = static_cast<tcflag_t>((tio.c_cflag & ~static_cast<tcflag_t>(CSTOPB | CRTSCTS)) | CLOCAL | CREAD);
    ::cfsetispeed(&tio, baud_constant(baud));
    ::cfsetospeed(&tio, baud_constant(baud));
    if (::tcsetattr(fd_, TCSANOW, &tio) != 0) {
        sys_error(device);
    }
    ::tcflush(fd_, TCIOFLUSH);
}

SerialTransport::~SerialTransport() {
    if (fd_ >= 0) {
        ::close(fd_);
    }
}

void SerialTransport::write(const std::uint8_t* p, std::size_t n) {
    write_all(fd_, p, n, device_);
}
std::size_t SerialTransport::read(std::uint8_t* p, std::size_t cap, int timeout_ms) {
    return read_some(fd_, p, cap, timeout_ms, device_);
}

ProcessTransport::ProcessTransport(const std::vector<std::string>& argv) : argv_(argv) {
    if (argv_.empty()) {
        throw std::runtime_error("ProcessTransport: empty command");
    }
    start();
}

ProcessTransport::~ProcessTransport() {
    stop();
}

void ProcessTransport::start() {
    int in[2];
    int out[2];
    if (::pipe2(in, O_CLOEXEC) != 0 || ::pipe2(out, O_CLOEXEC) != 0) {
        sys_error("pipe");
    }
    std::vector<char*> args;
    for (auto& a : argv_) {
        args.push_back(a.data());
    }
    args.push_back(nullptr);
    const pid_t parent = ::getpid();
    // Forked and registered with the cleanup signals held: a signal in
    // between still finds the child to kill.
    const CleanupSignalsHeld held;
    pid_ = ::fork();
    if (pid_ < 0) {
        sys_error("fork");
    }
    if (pid_ == 0) {
        ::pthread_sigmask(SIG_SETMASK, &held.previous(), nullptr);  // the emulator runs with our mask
        // Die with the parent, even when it is SIGKILLed; if it died before
        // prctl took effect, we have been reparented already: leave now.
        if (::prctl(PR_SET_PDEATHSIG, SIGKILL) != 0 || ::getppid() != parent) {
            ::_exit(127);
        }
        ::dup2(in[0], STDIN_FILENO);
        ::dup2(out[1], STDOUT_FILENO);
        ::execvp(args[0], args.data());
        text::c_fprintf(stderr, "ascorr: cannot run %s: %s\n", args[0], std::strerror(errno));
        ::_exit(127);
    }
    cleanup_slot_ = cleanup_register_child(pid_);
    ::close(in[0]);
    ::close(out[1]);
    to_child_ = in[1];
    from_child_ = out[0];
    ::signal(SIGPIPE, SIG_IGN);  // a dead child shows as EPIPE, reported as an error
}

void ProcessTransport::stop() {
    if (to_child_ >= 0) {
        ::close(to_child_);
        to_child_ = -1;
    }
    if (from_child_ >= 0) {
        ::close(from_child_);
        from_child_ = -1;
    }
    if (pid_ > 0) {
        ::kill(pid_, SIGTERM);
        int status = 0;
        ::waitpid(pid_, &status, 0);
        cleanup_release(cleanup_slot_);
        cleanup_slot_ = -1;
        pid_ = -1;
    }
}

void ProcessTransport::restart() {
    stop();
    start();
}

void ProcessTransport::write(const std::uint8_t* p, std::size_t n) {
    write_all(to_child_, p, n, argv_[0]);
}
std::size_t ProcessTransport::read(std::uint8_t* p, std::size_t cap, int timeout_ms) {
    return read_some(from_child_, p, cap, timeout_ms, argv_[0]);
}

void LoopbackTransport::write(const std::uint8_t* p, std::size_t n) {
    serve_(p, n, [this](const std::uint8_t* r, std::size_t m) { pending_.insert(pending_.end(), r, r + m); });
}

std::size_t LoopbackTransport::read(std::uint8_t* p, std::size_t cap, int /*timeout_ms*/) {
    std::size_t n = 0;
    while (n < cap && !pending_.empty()) {
        p[n++] = pending_.front();
        pending_.pop_front();
    }
    return n;  // nothing pending: the in-process target has nothing to say, a time-out at once
}

std::vector<std::uint8_t> FaultInjector::mangle(std::vector<std::uint8_t> frame, FaultCounts& counts) {
    std::uniform_real_distribution<double> u(0.0, 1.0);
    if (frame.size() < 2 || u(rng_) >= rate_) {
        return frame;
    }
    const std::size_t body = frame.size() - 1;  // without the delimiter
    switch (std::uniform_int_distribution<int>(0, 3)(rng_)) {
        case 0: {  // flip one bit of the body
            const std::size_t at = std::uniform_int_distribution<std::size_t>(0, body - 1)(rng_);
            frame[at] = static_cast<std::uint8_t>(frame[at] ^ (1U << std::uniform_int_distribution<int>(0, 7)(rng_)));
            ++counts.corrupted;
            return frame;
        }
        case 1:
            ++counts.dropped;
            return {};
        case 2: {
            ++counts.duplicated;
            std::vector<std::uint8_t> twice = frame;
            twice.insert(twice.end(), frame.begin(), frame.end());
            return twice;
        }
        default: {
            const std::size_t keep = std::uniform_int_distribution<std::size_t>(0, body - 1)(rng_);
            std::vector<std::uint8_t> cut(frame.begin(), frame.begin() + static_cast<std::ptrdiff_t>(keep));
            cut.push_back(0);
            ++counts.truncated;
            return cut;
        }
    }
}

void FaultInjector::write(const std::uint8_t* p, std::size_t n) {
    std::vector<std::uint8_t> frame;
    for (std::size_t i = 0; i < n; ++i) {
        frame.push_back(p[i]);
        if (p[i] == 0U || i + 1 == n) {
            const auto out = mangle(std::move(frame), to_target_);
            if (!out.empty()) {
                inner_.write(out.data(), out.size());
            }
            frame.clear();
        }
    }
}

std::size_t FaultInjector::read(std::uint8_t* p, std::size_t cap, int timeout_ms) {
    // Frames are faulted whole, so bytes are held until their frame is
    // complete; reading on until then (or the time-out) keeps a frame that
    // arrives in pieces (a UART, QEMU: byte by byte) from looking like a
    // time-out to the caller.
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::milliseconds(timeout_ms);
    while (ready_in_.empty()) {
        const auto left =
            std::chrono::duration_cast<std::chrono::milliseconds>(deadline - std::chrono::steady_clock::now());
        std::uint8_t buf[512];
        const std::size_t n = inner_.read(buf, sizeof buf, static_cast<int>(std::max<long long>(0, left.count())));
        if (n == 0) {
            break;
        }
        for (std::size_t i = 0; i < n; ++i) {
            partial_in_.push_back(buf[i]);
            if (buf[i] == 0U) {
                const auto out = mangle(std::move(partial_in_), to_host_);
                ready_in_.insert(ready_in_.end(), out.begin(), out.end());
                partial_in_.clear();
            }
        }
    }
    std::size_t n = 0;
    while (n < cap && !ready_in_.empty()) {
        p[n++] = ready_in_.front();
        ready_in_.pop_front();
    }
    return n;
}

}  // namespace ascorr::host
