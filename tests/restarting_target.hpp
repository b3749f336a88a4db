// tests/restarting_target.hpp: the link server behind a loopback transport,
// restarting (its state lost, a fresh boot id announced) after a given
// number of answers: what a DPU's reset looks like to the host's client.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>

#include "ascorr_host/link/link_transport.hpp"
#include "ascorr_link/server.hpp"

namespace ascorr::test {

// The target restarts (its state lost) after `restart_after` answers and
// announces it.
class RestartingTarget {
public:
    struct Counter {
        std::uint32_t operator()() const { return 0; }
    };
    using Server = link::LinkServer<float, Counter>;

    explicit RestartingTarget(int restart_after)
        : restart_after_(restart_after), server_(std::make_unique<Server>(1, Counter{})) {}

    void serve(const std::uint8_t* p, std::size_t n, const host::LoopbackTransport::Reply& reply) {
        for (std::size_t i = 0; i < n; ++i) {
            if (p[i] == 0U && answers_ == restart_after_) {
                ++answers_;
                server_ = std::make_unique<Server>(2, Counter{});
                server_->announce(reply);
                continue;
            }
            server_->on_byte(p[i], [&](const std::uint8_t* r, std::size_t m) {
                ++answers_;
                reply(r, m);
            });
        }
    }

private:
    int restart_after_;
    int answers_ = 0;
    std::unique_ptr<Server> server_;
};

}  // namespace ascorr::test
