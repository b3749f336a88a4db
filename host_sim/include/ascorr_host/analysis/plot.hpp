// ascorr_host/analysis/plot.hpp: IBA figures like the paper's Figs. 5–7 (`ascorr plot`).
//
// One panel per pair: the IBA of the original, aberration-corrected and
// thermal-corrected solutions (clean epochs, as `stats`) minus each stage's
// mean, as means over 90-minute bins (about one orbit) so that the seasonal
// signal stands out of the star-tracker noise; the legend gives the RMS of
// the unbinned IBA. The modelling period, when given, is shaded.
// With --temperatures, two panels under them on the same time axis (the
// paper's Fig. 4): T_CHU of A, B and C, and T029 and T032, as means over the
// same bins. With a window (--window-from/--window-to, e.g. heater-test days,
// the paper's Figs. 8–9) only the epochs in it are drawn: the IBA of each
// stage as a running mean over 200 s (the smoothing of `stats`) about its
// mean in the window, the temperatures as means over 200 s bins. Drawn by
// gnuplot (pngcairo terminal, or png if this gnuplot lacks cairo); the PNG is
// written to a temporary file and renamed, so it is whole or absent.
#pragma once

#include <cstddef>
#include <iosfwd>
#include <optional>
#include <string>

namespace ascorr::host {

inline constexpr double kPlotBinS = 5400.0;

struct PlotOptions {
    std::string in;
    std::string model;
    std::string out;
    std::optional<double> period_from;  // modelling period to shade
    std::optional<double> period_to;
    bool temperatures = false;          // add the temperature panels
    std::optional<double> window_from;  // draw only [window_from, window_to]
    std::optional<double> window_to;
    int width = 1400;  // pixels; each panel is 2/7 of it high
    std::string gnuplot = "gnuplot";
};

// Throws InputError, std::runtime_error (gnuplot missing or failing, a
// window that is empty or has no clean epoch).
void plot_iba(const PlotOptions& opt, std::ostream& log);

// The combined attitude's error against the truth in a window (`plot
// --combined A --truth-attitude T --window-from --window-to`): three panels,
// the error about CRF x, y and z (arcsec, combined_stats.hpp's θ), each epoch
// a point coloured by its head set, the epochs without the full set shaded
// grey (the head set has changed: where a step would show).
struct CombinedPlotOptions {
    std::string combined;
    std::string truth;
    std::string out;
    double from = 0.0;
    double to = 0.0;
    int width = 1400;
    std::string gnuplot = "gnuplot";
};
void plot_combined(const CombinedPlotOptions& opt, std::ostream& log);

// Writes "t+time_offset T_CHU_A … T_CHU_<last head of heads.hpp> T029 T032"
// per bin of bin_s seconds with data in [from, to] (means over the rows of
// each head; NaN where a bin has none of a temperature). Returns the number of bins.
std::size_t write_temperature_series(const std::string& in, const std::string& path, double bin_s,
                                     std::optional<double> from, std::optional<double> to, double time_offset);

}  // namespace ascorr::host
