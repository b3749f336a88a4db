// ascorr_host/plot.hpp: IBA figures like the paper's Figs. 5–7 (`ascorr plot`).
//
// One panel per pair: the IBA of the original, aberration-corrected and
// thermal-corrected solutions (clean epochs, as `stats`) minus each stage's
// mean, as means over 90-minute bins (about one orbit) so that the seasonal
// signal stands out of the star-tracker noise; the legend gives the RMS of
// the unbinned IBA. The modelling period, when given, is shaded. Drawn by
// gnuplot (pngcairo terminal, or png if this gnuplot lacks cairo); the PNG is
// written to a temporary file and renamed, so it is whole or absent.
#pragma once

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
    std::string gnuplot = "gnuplot";
};

// Throws InputError, std::runtime_error (gnuplot missing or failing).
void plot_iba(const PlotOptions& opt, std::ostream& log);

}  // namespace ascorr::host
