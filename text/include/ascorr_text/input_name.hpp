// ascorr_text/input_name.hpp: the name by which messages show an input.
//
// An input is shown by its path, except where the command line reads it
// through a stand-in: standard input ("-") is copied to a private temporary
// file first (host_sim/cli/standard_input.cpp), and every message about that
// file says "standard input", with its line and column, never the copy's
// path. Used by every reader's InputError (input_error.hpp) and the
// correction's diagnostics, so that all of them say it alike.
//
// Stand-ins are named once, before any input is read; reading the names
// concurrently (the correction's worker threads) is then safe.
#pragma once

#include <string>
#include <utility>
#include <vector>

namespace ascorr::text {

namespace detail {
inline std::vector<std::pair<std::string, std::string>>& input_names() {
    static std::vector<std::pair<std::string, std::string>> names;
    return names;
}
}  // namespace detail

// From now on, messages show the input at `path` as `name`.
inline void show_input_as(std::string path, std::string name) {
    detail::input_names().emplace_back(std::move(path), std::move(name));
}

// The name by which messages show the input at `path`.
inline std::string input_name(const std::string& path) {
    for (const auto& [p, name] : detail::input_names()) {
        if (p == path) {
            return name;
        }
    }
    return path;
}

}  // namespace ascorr::text
