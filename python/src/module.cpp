// python/src/module.cpp: the compiled part of `import ascorr` (pybind11).
//
// Glue only: every number comes from the core headers (firmware/include/) and
// the host library (host_sim/, ascorr_host), the same code as the command
// line. The bindings are split by topic (bind_model, bind_formats,
// bind_correct, bind_self_calibration, bind_analysis, bind_combine,
// bind_interpolate, bind_gracefo), their argument checks shared (bind.hpp,
// arguments.cpp), their docstrings written once (docstrings.hpp).
#include <pybind11/pybind11.h>

#include "ascorr/core/heads.hpp"
#include "ascorr_host/analysis/fit.hpp"
#include "ascorr_text/input_error.hpp"
#include "bind.hpp"
#include "docstrings.hpp"

PYBIND11_MODULE(_ascorr, mod) {
    namespace py = pybind11;
    using namespace ascorr;
    using namespace ascorr::python;
    mod.doc() = docs::kModule;

    // Malformed input and refused fits are ValueErrors; other failures of the
    // host library (a file that cannot be written, a model beyond the fixed-point
    // formats) are std::runtime_error, hence RuntimeError.
    py::register_exception<text::InputError>(mod, "InputError", PyExc_ValueError).attr("__doc__") = docs::kInputError;
    py::register_exception<host::FitRefused>(mod, "FitRefused", PyExc_ValueError).attr("__doc__") = docs::kFitRefused;

    // The heads (ascorr/core/heads.hpp), for Python and for the docstrings.
    mod.attr("HEADS") = py::str(kHeadLetters);
    // The model's terms, the model file's columns (ascorr/core/model_terms.hpp).
    py::tuple terms(kModelTerms);
    for (std::size_t k = 0; k < kModelTerms; ++k) {
        terms[k] = py::str(kModelTermTable[k].name);
    }
    mod.attr("MODEL_TERMS") = terms;

    bind_model(mod);
    bind_formats(mod);
    bind_correct(mod);
    bind_self_calibration(mod);
    bind_analysis(mod);
    bind_combine(mod);
    bind_interpolate(mod);
    bind_gracefo(mod);
}
