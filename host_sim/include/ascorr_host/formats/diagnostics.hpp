// ascorr_host/formats/diagnostics.hpp: messages about bad input, without flooding.
//
// A recorded mission can hold millions of rows with the same defect. Each kind
// of message is printed for its first `limit` occurrences; the rest are
// counted and summarised at the end, so every defect is accounted for.
#pragma once

#include <map>
#include <ostream>
#include <string>

namespace ascorr::host {

class Diagnostics {
public:
    explicit Diagnostics(std::ostream& out, std::size_t limit = 20) : out_(out), limit_(limit) {}

    // kind groups messages for throttling ("not unit", "bad velocity", ...).
    void report(const std::string& kind, const std::string& message);
    // One line per kind that was cut short.
    void summarize();
    std::size_t count(const std::string& kind) const;
    std::size_t total() const;

private:
    std::ostream& out_;
    std::size_t limit_;
    std::map<std::string, std::size_t> counts_;
};

}  // namespace ascorr::host
