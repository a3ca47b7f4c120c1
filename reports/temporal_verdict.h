// The specular-AA verdict of a temporal run (issue 28), from the run's own results: for each temporal
// scene (scene, environment, shading path) every specular_aa variant's flicker and FLIP against the
// temporal truth, as a change from specular_aa=off's figures in the same test (results' temporal.truth
// and temporal.truth.off). A variant helps where it flickers less than off and its FLIP vs the truth is
// within kVerdictFlipTolerance of off's; the paragraph names those, or says why none does.
#pragma once
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace iblcheck::report {

// "Without costing accuracy": FLIP vs the truth at most 5 % above off's (the temporal suite's bands
// are 15 %; 5 % is well inside run-to-run noise of none, the figures are deterministic).
inline constexpr double kVerdictFlipTolerance = 0.05;

struct AaOutcome {
    std::string scene;         // "bumpy_sphere · sky_sun" (· shading=fragment where the test sets it)
    std::string variant;       // its AA parameters ("specular_aa=toksvig,specular_aa_variance=0.02")
    std::string test;          // its name
    double flicker_change = 0; // flicker / off's − 1, against the truth
    double flip_change = 0;    // mean FLIP / off's − 1, against the truth
    bool helps = false;
};

// Every temporal test with truth figures and an `off` beside them, except off itself, in input order.
std::vector<AaOutcome> aa_outcomes(const std::vector<const nlohmann::json*>& tests);

// One sentence per scene (in order of first appearance): the variants that help, or "none", with the
// figures of the nearest miss and why each misses (flickers more, costs FLIP, or both).
std::vector<std::string> aa_verdict_lines(const std::vector<AaOutcome>& outcomes);

// The temporal section's verdict paragraph and its chart (flicker change against FLIP change vs off,
// one panel per scene); "" when no test has truth figures.
std::string aa_verdict_html(const std::vector<const nlohmann::json*>& tests);

} // namespace iblcheck::report
