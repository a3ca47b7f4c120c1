// The golden store (goldens/): two kinds kept apart.
//   reference/<key>.exr + .json   ground truth from the reference integrator (accuracy is measured
//                                  against it); key = <scene>__<env> (see reference_key)
//   baseline/<test>.exr + .json   the approved output of a tested configuration; alternates
//                                  baseline/<test>@<label>.exr are further approved outputs (a known
//                                  platform difference is approved, not hidden by a wider tolerance)
// Every golden has a JSON sidecar of provenance. GoldenStore::write_golden is the one writer of goldens
// (`iblcheck bless`, and `iblcheck truth`, which the reference regeneration script runs), atomically:
// image and sidecar go to temporary files that are renamed into place, so a reader never sees a
// half-written golden. reference_key is the one place reference goldens are named (the script asks
// `iblcheck truth --print-name`).
#pragma once
#include <filesystem>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>
#include <optional>
#include <string>
#include <vector>

#include "renderers/render_api.h"

namespace iblcheck {

struct Golden {
    std::filesystem::path image_path;
    cv::Mat image;                                        // CV_32FC3 linear
    nlohmann::json provenance = nlohmann::json::object(); // sidecar
    std::string label;                                    // "" for the primary baseline, else the @label
};

class GoldenStore {
  public:
    // root: --goldens, else $IBLCHECK_GOLDEN_DIR, else <source>/goldens.
    explicit GoldenStore(std::filesystem::path root = {});
    const std::filesystem::path& root() const { return root_; }
    // Before judging against it: the root is a folder holding baseline/ or reference/. A wrong
    // --goldens used to make every test missing-golden (exit 1, a regression). Throws InputError.
    void check_root() const;

    // All approved baselines of a test (primary first). Throws InputError naming the file on a
    // corrupt golden, one that is not an R, G, B OpenEXR, one with NaN/Inf pixels, or one without
    // its sidecar.
    std::vector<Golden> baselines(const std::string& test_name) const;
    std::optional<Golden> reference(const TestSpec& spec) const;
    std::filesystem::path baseline_path(const std::string& test_name, const std::string& label = "") const;
    std::filesystem::path reference_path(const TestSpec& spec) const;
    // The temporal truth of a sequence of `frames` frames: reference/<key>__frames=N.exr, the frames
    // stacked vertically (harness/truth/truth_golden.h), split into frames; nullopt when absent.
    // Throws InputError naming the file when it is corrupt, has no sidecar or NaN/Inf pixels, or its
    // height is not a multiple of `frames`.
    std::optional<Golden> reference_sequence(const TestSpec& spec, int frames, std::vector<cv::Mat>& out) const;
    std::filesystem::path reference_sequence_path(const TestSpec& spec, int frames) const;

    // Atomically writes image + sidecar (each through a temporary file renamed into place, the sidecar
    // first), creating the folder. An EXR whose pixels are bit-identical to `image` is kept (only the
    // sidecar is rewritten). Throws InputError naming the path when it cannot.
    static void write_golden(const std::filesystem::path& exr, const cv::Mat& image, const nlohmann::json& provenance);
    // Atomically rewrites the sidecar of `exr` only (the pixels are unchanged).
    static void write_sidecar(const std::filesystem::path& exr, const nlohmann::json& provenance);
    // `p` relative to the golden root (as results and sidecars name goldens), or `p` if outside it.
    std::string relative(const std::filesystem::path& p) const;

  private:
    std::filesystem::path root_;
};

// <scene>__<env>: the environment's stable name (environment_label: a built-in spec with ':' as '-', a
// file's suite-given name or its file name, never its folder), material options of single-sphere scenes
// (roughness, metallic, base_color), a non-default size and env_rotation are appended, since they
// change the true image.
std::string reference_key(const TestSpec& spec);
// The temporal truth of `frames` frames: reference_key(spec) + "__frames=N".
std::string reference_sequence_key(const TestSpec& spec, int frames);
// The command that renders the truth `spec` asks for into `store` under reference_key(spec): what a
// test whose truth is missing prints (iblcheck truth ... --env FILE [--env-name N] [--size WxH]
// [--set k=v] [--goldens ROOT]).
std::string truth_command(const TestSpec& spec, const GoldenStore& store);
// The environment content hash a truth sidecar records (env.content_hash); "" when it has none.
std::string truth_env_hash(const nlohmann::json& sidecar);
// File-system-safe form of a test name.
std::string safe_file_name(const std::string& name);

// Provenance common to every golden and every run: project commit, date, CPU features.
std::string project_commit(bool* dirty = nullptr);
std::string utc_now_iso();
std::vector<std::string> cpu_features();

} // namespace iblcheck
