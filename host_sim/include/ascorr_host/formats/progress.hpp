// ascorr_host/formats/progress.hpp: a percentage on the terminal for long jobs.
//
// Shown only when stderr is a terminal, so that logs and pipes stay clean;
// redrawn only when the whole percent changes, so it costs nothing per row.
#pragma once

#include <string>

namespace ascorr::host {

class Progress {
public:
    explicit Progress(std::string label);
    ~Progress();
    Progress(const Progress&) = delete;
    Progress& operator=(const Progress&) = delete;

    void update(double fraction);  // 0..1
    void done();                   // clears the line

private:
    std::string label_;
    bool enabled_;
    int shown_ = -1;
};

}  // namespace ascorr::host
