// ascorr/pipeline/version_sun_term.hpp: the Sun term each model version of
// the on-board estimator takes (docs/contract.md, "The Sun term learnt in
// self-calibration" and "The Sun term learnt on the link"), for the link
// server and the flight loop alike.
//
// Conventions: at the first epoch of a version (after EpochPipeline::begin,
// with a model), the term the learner has taken then (calib/sun_learner.hpp,
// SunLearner::version_term: its candidate as of the last epoch it took), for
// the heads the version has, kept in arcsec (what CALIB_SUN_TERM reports)
// and in T (sun_term_from_arcsec, the one conversion the host's model reader
// uses too), and given to the pipeline, which applies it after the feed
// (use_sun_term). Later epochs of the same version change nothing. The
// learner takes an epoch's frame heads only where the estimator took its
// feed (learner_takes_feed). No allocation; loops over the heads only.
#pragma once

#include <cstdint>

#include "../calib/sun_learner.hpp"
#include "../core/heads.hpp"
#include "../core/model_coefficients.hpp"
#include "../core/sun_term.hpp"

namespace ascorr::pipeline {

template <typename T>
struct VersionSunTerm {
    bool set = false;  // version is the last one seen with a model
    std::uint32_t version = 0U;
    double arcsec[kMaxHeads][kModelAxes][kSunComponents] = {};
    SunTermModel<T> model{};

    // At an epoch begun: nothing unless it has a model of a version new here
    // (active: the estimator's active coefficients, nullptr: none).
    template <typename Pipeline>
    void follow(const calib::SunLearner& learner, const ModelCoefficients* active, Pipeline& pipeline) noexcept {
        if (pipeline.model() == nullptr || active == nullptr || (set && version == pipeline.version())) {
            return;
        }
        set = true;
        version = pipeline.version();
        learner.version_term(heads_where(active->present), arcsec);
        model = sun_term_from_arcsec<T>(arcsec);
        pipeline.use_sun_term(any_sun_term(model) ? &model : nullptr);
    }
};

// Whether an epoch's feed goes to the learner too: the estimator took it
// (the pipeline's feeds grew past feeds_before) under a model, and is not
// frozen (frozen, it takes nothing from the feed: nor does the learner).
template <typename Pipeline, typename Estimator>
bool learner_takes_feed(const Pipeline& pipeline, std::uint32_t feeds_before, const Estimator& estimator) noexcept {
    return pipeline.feeds() != feeds_before && pipeline.model() != nullptr && !estimator.frozen();
}

}  // namespace ascorr::pipeline
