// libFuzzer: the firmware's link server (frame decoder, message decoders,
// correction) on arbitrary bytes. Properties checked beyond "no crash, no UB":
// every byte sequence the server sends back is a well-formed frame.
#include <cstddef>
#include <cstdint>
#include <cstdlib>

#include "ascorr_link/server.hpp"

namespace {
struct Counter {
    std::uint32_t operator()() const { return 0; }
};
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    ascorr::link::LinkServer<float, Counter> server(1, Counter{});
    auto check = [](const std::uint8_t* p, std::size_t n) {
        ascorr::link::FrameDecoder d;
        std::size_t frames = 0;
        for (std::size_t i = 0; i < n; ++i) {
            const auto e = d.push(p[i]);
            if (e == ascorr::link::FrameDecoder::Event::kError) {
                std::abort();  // the server emitted a broken frame
            }
            frames += e == ascorr::link::FrameDecoder::Event::kFrame ? 1U : 0U;
        }
        if (frames != 1) {
            std::abort();  // one response is exactly one frame
        }
    };
    for (std::size_t i = 0; i < size; ++i) {
        server.on_byte(data[i], check);
    }
    return 0;
}
