#include "metrics_store.h"

#include <cstdint>
#include <cstring>

#include "image_io/image_hash.h"
#include "kernel/hash.h"
#include "kernel/store_entry.h"
#include "renderers/vulkan/shader_compiler.h"

namespace fs = std::filesystem;
using nlohmann::json;

namespace iblcheck {

namespace {

constexpr char kMagic[] = "IBLMETR1"; // this layout; another is a miss

fs::path entry_path(const std::string& key) { return metrics_store_dir() / (key + ".metrics"); }

// A double as its bits: the stored figures are the computed ones exactly, not a decimal rounding.
uint64_t bits_of(double v) {
    uint64_t b = 0;
    std::memcpy(&b, &v, sizeof b);
    return b;
}
double double_of(const json& j) {
    const uint64_t b = j.get<uint64_t>();
    double v = 0;
    std::memcpy(&v, &b, sizeof v);
    return v;
}

// Every figure of a FlipResult but its map (stored after the header, raw).
json flip_scalars(const FlipResult& r) {
    return {{"rows", r.errmap.rows},
            {"cols", r.errmap.cols},
            {"mean", bits_of(r.mean)},
            {"weighted_median", bits_of(r.weighted_median)},
            {"weighted_q1", bits_of(r.weighted_q1)},
            {"weighted_q3", bits_of(r.weighted_q3)},
            {"p99", bits_of(r.p99)},
            {"min", bits_of(r.min)},
            {"max", bits_of(r.max)},
            {"block_max", bits_of(r.block_max)},
            {"block_x", r.block_x},
            {"block_y", r.block_y},
            {"mode", r.mode},
            {"ppd", bits_of(r.ppd)},
            {"start_exposure", bits_of(r.start_exposure)},
            {"stop_exposure", bits_of(r.stop_exposure)},
            {"num_exposures", r.num_exposures},
            {"exposure_source", r.exposure_source}};
}

// The FlipResult of `j` with its map read from `data` (advanced past it); false if `size` is short.
bool read_flip(const json& j, const char*& data, size_t& size, FlipResult& r) {
    const int rows = j.at("rows").get<int>(), cols = j.at("cols").get<int>();
    if (rows < 0 || cols < 0) return false;
    const size_t n = size_t(rows) * size_t(cols) * sizeof(float);
    if (n > size) return false;
    r.errmap = cv::Mat(rows, cols, CV_32F);
    if (n) std::memcpy(r.errmap.data, data, n);
    data += n, size -= n;
    r.mean = double_of(j.at("mean"));
    r.weighted_median = double_of(j.at("weighted_median"));
    r.weighted_q1 = double_of(j.at("weighted_q1"));
    r.weighted_q3 = double_of(j.at("weighted_q3"));
    r.p99 = double_of(j.at("p99"));
    r.min = double_of(j.at("min"));
    r.max = double_of(j.at("max"));
    r.block_max = double_of(j.at("block_max"));
    r.block_x = j.at("block_x").get<int>();
    r.block_y = j.at("block_y").get<int>();
    r.mode = j.at("mode").get<std::string>();
    r.ppd = double_of(j.at("ppd"));
    r.start_exposure = double_of(j.at("start_exposure"));
    r.stop_exposure = double_of(j.at("stop_exposure"));
    r.num_exposures = j.at("num_exposures").get<int>();
    r.exposure_source = j.at("exposure_source").get<std::string>();
    return true;
}

void append_map(std::string& bytes, const FlipResult& r) {
    const cv::Mat m = r.errmap.isContinuous() ? r.errmap : r.errmap.clone();
    if (!m.empty()) bytes.append(reinterpret_cast<const char*>(m.data), m.total() * sizeof(float));
}

} // namespace

fs::path metrics_store_dir() { return store_dir("IBLCHECK_METRICS_CACHE", vk::spirv_cache_dir().parent_path() / "metrics"); }

std::string metrics_store_key(const cv::Mat& golden, const cv::Mat& test, const DisplaySpace* display, const std::string& tool) {
    Fnv1a64 h;
    h.update("tool=" + tool + ";" + kMagic + ";");
    h.update("display=" + (display ? display_json(*display).dump() : std::string("none")) + ";");
    hash_image(h, golden);
    hash_image(h, test);
    return h.hex();
}

std::optional<Measured> load_measured(const std::string& key) {
    if (metrics_store_dir().empty()) return std::nullopt;
    // The magic, the key again (a renamed or misplaced file is a miss), the header's length, the
    // header (JSON), the maps.
    const std::optional<std::string> entry = read_store_entry(entry_path(key), std::string(kMagic) + key);
    uint64_t header_size = 0;
    if (!entry || entry->size() < sizeof header_size) return std::nullopt;
    std::memcpy(&header_size, entry->data(), sizeof header_size);
    const char* data = entry->data() + sizeof header_size;
    size_t size = entry->size() - sizeof header_size;
    if (header_size > size) return std::nullopt;
    try {
        const json header = json::parse(data, data + header_size);
        data += header_size, size -= header_size;
        Measured m;
        m.metrics = header.at("metrics");
        if (!read_flip(header.at("linear"), data, size, m.linear)) return std::nullopt;
        if (!header.at("shown").is_null()) {
            m.shown.emplace();
            if (!read_flip(header.at("shown"), data, size, *m.shown)) return std::nullopt;
        }
        if (size != 0) return std::nullopt; // a longer file is not one this code wrote
        return m;
    } catch (const json::exception&) {
        return std::nullopt; // damaged: computed again
    }
}

void save_measured(const std::string& key, const Measured& m) {
    if (metrics_store_dir().empty()) return;
    const json header = {
        {"metrics", m.metrics}, {"linear", flip_scalars(m.linear)}, {"shown", m.shown ? flip_scalars(*m.shown) : json()}};
    const std::string text = header.dump();
    // Only what reads back as it was: a NaN in the metrics (null in JSON) is measured again.
    if (json::parse(text).at("metrics") != m.metrics) return;
    std::string bytes = std::string(kMagic) + key;
    const uint64_t header_size = text.size();
    bytes.append(reinterpret_cast<const char*>(&header_size), sizeof header_size);
    bytes += text;
    append_map(bytes, m.linear);
    if (m.shown) append_map(bytes, *m.shown);
    write_store_entry(entry_path(key), bytes); // a failure is no error: the next run measures again
}

} // namespace iblcheck
