#include "sequence_store.h"

#include <cstdint>
#include <cstring>

#include "kernel/cpu_caps.h"
#include "kernel/hash.h"
#include "kernel/store_entry.h"
#include "renderers/vulkan/shader_compiler.h"

namespace iblcheck {

namespace {

constexpr char kMagic[] = "IBLSEQ01"; // this layout; another is a miss

// A frame's header: its size and OpenCV type, as 32-bit values.
struct FrameShape {
    int32_t rows = 0, cols = 0, type = 0;
    size_t bytes() const { return size_t(rows) * size_t(cols) * CV_ELEM_SIZE(type); }
};

// The provenance's part that stands for an input; "none" where the render did not record it.
std::string part(const nlohmann::json& provenance, const char* key) {
    const auto it = provenance.find(key);
    return it == provenance.end() ? "none" : it->dump();
}

} // namespace

std::string sequence_spec_text(TestSpec s, int frames) {
    s.options.erase("frame"); // the sequence's frames, all of them
    return s.method + "|" + s.scene + "|" + s.env + "|" + s.env_name + "|" + std::to_string(s.width) + "x" +
           std::to_string(s.height) + "|" + s.options.canonical() + "|frame=" + std::to_string(s.frame) + "|" + s.shader +
           "|frames=" + std::to_string(frames);
}

std::filesystem::path sequence_store_dir() {
    return store_dir("IBLCHECK_SEQUENCE_CACHE", vk::spirv_cache_dir().parent_path() / "sequences");
}

std::string sequence_store_key(const TestSpec& spec, int frames, const nlohmann::json& provenance, const std::string& tool) {
    Fnv1a64 h;
    h.update("tool=" + tool + ";" + kMagic + ";");
    h.update(sequence_spec_text(spec, frames) + ";");
    for (const char* key : {"shader_tree_hash", "driver", "env_hash"})
        h.update(std::string(key) + "=" + part(provenance, key) + ";");
    h.update("cpu=" + llvmpipe_caps().cpu_class());
    return h.hex();
}

std::optional<std::vector<cv::Mat>> load_sequence(const std::string& key, const cv::Mat& first, int frames) {
    if (sequence_store_dir().empty() || frames < 1) return std::nullopt;
    const std::optional<std::string> entry =
        read_store_entry(sequence_store_dir() / (key + ".frames"), std::string(kMagic) + key);
    FrameShape shape;
    if (!entry || entry->size() < sizeof shape) return std::nullopt;
    std::memcpy(&shape, entry->data(), sizeof shape);
    const cv::Mat f0 = first.isContinuous() ? first : first.clone();
    if (shape.rows != f0.rows || shape.cols != f0.cols || shape.type != f0.type()) return std::nullopt;
    const size_t n = shape.bytes();
    if (entry->size() != sizeof shape + n * size_t(frames)) return std::nullopt; // another count, or damaged
    const char* data = entry->data() + sizeof shape;
    if (n && std::memcmp(data, f0.data, n) != 0) return std::nullopt; // the first frame renders differently now
    std::vector<cv::Mat> out;
    for (int k = 0; k < frames; ++k, data += n) {
        cv::Mat m(shape.rows, shape.cols, shape.type);
        if (n) std::memcpy(m.data, data, n);
        out.push_back(std::move(m));
    }
    return out;
}

void save_sequence(const std::string& key, const std::vector<cv::Mat>& frames) {
    if (sequence_store_dir().empty() || frames.empty()) return;
    const FrameShape shape{frames[0].rows, frames[0].cols, frames[0].type()};
    std::string bytes = std::string(kMagic) + key;
    bytes.append(reinterpret_cast<const char*>(&shape), sizeof shape);
    for (const cv::Mat& f : frames) {
        if (f.rows != shape.rows || f.cols != shape.cols || f.type() != shape.type) return; // not one sequence
        const cv::Mat m = f.isContinuous() ? f : f.clone();
        bytes.append(reinterpret_cast<const char*>(m.data), shape.bytes());
    }
    write_store_entry(sequence_store_dir() / (key + ".frames"), bytes);
}

} // namespace iblcheck
