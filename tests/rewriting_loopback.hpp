// tests/rewriting_loopback.hpp: a loopback target (a float LinkServer behind
// host::LoopbackTransport) whose incoming frames pass through a rewrite
// first: a test double that changes or records what the host sent, frame by
// frame (MOUNTING_LOAD turned, SOLUTION_IN's clean bit erased, build frames
// measured, a request's type made one the target does not know, as a
// firmware from before it would see it). The rewrite gets the frame's type
// and its payload, which it may change in place (with its new length); the
// frame is then encoded anew.
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <utility>

#include "ascorr_host/link/link_transport.hpp"
#include "ascorr_link/frame.hpp"
#include "ascorr_link/server.hpp"

namespace ascorr::test {

class RewritingLoopback {
public:
    using Rewrite = std::function<void(std::uint8_t& type, std::uint8_t* payload, std::size_t& length)>;

    explicit RewritingLoopback(Rewrite rewrite)
        : rewrite_(std::move(rewrite)),
          server_(0x54455354U, [] { return std::uint32_t{0}; }),
          transport_([this](const std::uint8_t* p, std::size_t n, const host::LoopbackTransport::Reply& reply) {
              for (std::size_t i = 0; i < n; ++i) {
                  pass(p[i], reply);
              }
          }) {}
    host::Transport& transport() { return transport_; }

private:
    void pass(std::uint8_t b, const host::LoopbackTransport::Reply& reply) {
        if (decoder_.push(b) != link::FrameDecoder::Event::kFrame) {
            return;
        }
        const link::Frame& f = decoder_.frame();
        std::uint8_t payload[link::kMaxPayload];
        std::size_t n = f.length;
        std::copy(f.payload, f.payload + n, payload);
        std::uint8_t type = f.type;
        rewrite_(type, payload, n);
        std::uint8_t wire[link::kMaxWire];
        const std::size_t w = link::encode_frame(type, f.seq, payload, n, wire, sizeof wire);
        for (std::size_t i = 0; i < w; ++i) {
            server_.on_byte(wire[i], reply);
        }
    }

    using Counter = std::uint32_t (*)();
    Rewrite rewrite_;
    link::FrameDecoder decoder_;
    link::LinkServer<float, Counter> server_;
    host::LoopbackTransport transport_;
};

}  // namespace ascorr::test
