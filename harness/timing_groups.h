// Timing groups (issue 33): tests whose frame is the same GPU work share their frame times.
//
// A suite that repeats timings (timing_repeats R > 1, the nightly's 3) renders each test R times for
// the median frame time and its range. Tests that differ only in their environment run the same
// shading pass on textures of the same size: the mobile method samples the prefiltered chain and the
// sampled method the source cube, both cube_size texels a face whatever the environment's file, and
// neither branches on texel values. Their frame times measure one thing. So the tests of such a
// group are rendered ceil(R / n) times each (n members), not R times, and every member reports the
// median and range of the group's samples: at least R of them when every member renders, as one
// test alone has, spread over the run.
//
// Measured on the nightly of 2026-11-27 (47 groups of four environments, 3 renders a test): the
// spread of the four environments' medians (median 7 %, p90 10 % of the median; renders minutes
// apart) was of the size of one test's own three (median 4 %, p90 11 %; renders a second apart),
// and no environment was faster throughout. The
// second and third renders of the groups' 188 tests were 59 s of frame time in a 175-s warm nightly.
//
// The grouping is checked after the renders, not assumed: a member whose render differs from the
// group's first in image size, texture texels or bytes, or deterministic cost (the counting twin's
// dynamic SPIR-V instructions and texture fetches per pixel, which any data-dependent branch would
// change) keeps its own samples and reports no group.
#pragma once
#include <string>
#include <vector>

#include "results/results.h"
#include "suite.h"

namespace iblcheck {

// The test's renders for its timing (1..20): its own timing_repeats, else the suite's.
int timing_repeats_of(const TestCase& tc, int suite_repeats);

// The test's timing group: its name with the environment as "*" (a pattern matching every member's
// name); members also share their renders and shader file. Empty when the test times itself alone:
// one render (nothing to share), or a method whose cost may depend on the environment (the CPU
// reference).
std::string timing_group(const TestCase& tc, int repeats);

// How many times to render each test: ceil(R / n) for a member of a group of n, R alone.
std::vector<int> timing_renders(const std::vector<TestCase>& tests, int suite_repeats);

// A render's frame times: `samples` sorted into frame_ms_samples, their median as frame_ms. The one
// place that says what a repeated timing reports (a test's own repeats and a group's alike).
void set_frame_samples(RenderFigures& f, std::vector<double> samples);

// After the renders: each group's members get the group's samples (sorted), their median as
// frame_ms, and the group's name in timing_group; a member that does not match the group (see
// above) or whose render failed keeps its own.
void share_timings(const std::vector<TestCase>& tests, int suite_repeats, std::vector<TestResult>& results);

} // namespace iblcheck
