// Linear image data for the page (float_data.h).
#include "reports/float_data.h"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>
#include <opencv2/imgproc.hpp>
#include <zlib.h>

#include "image_io/image_io.h"
#include "kernel/atomic_file.h"
#include "kernel/errors.h"
#include "kernel/hash.h"
#include "kernel/output_files.h"
#include "kernel/parallel_for.h"
#include "metrics/display_transform.h"
#include "metrics/flip/tone_mappers.h"

namespace iblcheck::report {

namespace fs = std::filesystem;

double auto_exposure(const cv::Mat& linear) {
    CV_Assert(linear.depth() == CV_32F);
    const int nc = linear.channels();
    std::vector<float> lum;
    lum.reserve(linear.total());
    for (int y = 0; y < linear.rows; ++y) {
        const float* p = linear.ptr<float>(y);
        for (int x = 0; x < linear.cols; ++x, p += nc) {
            const float l = nc >= 3 ? 0.2126f * p[0] + 0.7152f * p[1] + 0.0722f * p[2] : p[0];
            if (l > 0 && std::isfinite(l)) lum.push_back(l);
        }
    }
    if (lum.empty()) return 0;
    // Nearest rank: the smallest value with at least 99 % of the values at or below it.
    const size_t k = size_t(std::ceil(0.99 * double(lum.size()))) - 1;
    std::nth_element(lum.begin(), lum.begin() + long(k), lum.end());
    // The tone map is increasing: bisect tm(x) = 0.85 (the level HDR-FLIP's exposures aim at).
    const float* c = flip::kToneCoefficients[int(flip::ToneMapper::aces)];
    double lo = 0, hi = 1e4;
    for (int i = 0; i < 100; ++i) {
        const double mid = 0.5 * (lo + hi);
        (flip::tone_map_channel(float(mid), c) < 0.85f ? lo : hi) = mid;
    }
    const double ev = std::log2(0.5 * (lo + hi) / double(lum[k]));
    return std::round(std::clamp(ev, -20.0, 20.0) * 10.0) / 10.0;
}

std::vector<uint16_t> to_half(const cv::Mat& linear) {
    CV_Assert(linear.depth() == CV_32F);
    cv::Mat clamped = cv::min(cv::max(linear, -65504.0f), 65504.0f), h;
    clamped.convertTo(h, CV_16F);
    std::vector<uint16_t> out(h.total() * size_t(h.channels()));
    for (int y = 0; y < h.rows; ++y)
        std::memcpy(out.data() + size_t(y) * size_t(h.cols * h.channels()), h.ptr(y), size_t(h.cols * h.channels()) * 2);
    return out;
}

std::string pack_bytes(const std::vector<uint8_t>& bytes) {
    uLongf n = compressBound(uLong(bytes.size()));
    std::string out(n, '\0');
    if (compress2(reinterpret_cast<Bytef*>(out.data()), &n, bytes.data(), uLong(bytes.size()), Z_BEST_SPEED) != Z_OK)
        throw Error("report: zlib could not compress image data");
    out.resize(n);
    return out;
}

std::string pack_half(const std::vector<uint16_t>& half) {
    std::vector<uint8_t> planes(half.size() * 2);
    for (size_t i = 0; i < half.size(); ++i) {
        planes[i] = uint8_t(half[i] & 0xff);
        planes[half.size() + i] = uint8_t(half[i] >> 8);
    }
    return pack_bytes(planes);
}

std::vector<uint8_t> unpack(const std::string& packed) {
    z_stream s{};
    if (inflateInit(&s) != Z_OK) throw Error("zlib: inflateInit failed");
    std::vector<uint8_t> out;
    s.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(packed.data()));
    s.avail_in = uInt(packed.size());
    int rc = Z_OK;
    while (rc == Z_OK) {
        uint8_t buf[65536];
        s.next_out = buf;
        s.avail_out = sizeof buf;
        rc = inflate(&s, Z_NO_FLUSH);
        out.insert(out.end(), buf, buf + (sizeof buf - s.avail_out));
    }
    inflateEnd(&s);
    if (rc != Z_STREAM_END) throw Error("zlib: corrupt data");
    return out;
}

std::string base64(const std::string& in) {
    static const char* t = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    std::string out;
    out.reserve((in.size() + 2) / 3 * 4);
    size_t i = 0;
    for (; i + 2 < in.size(); i += 3) {
        const uint32_t v = uint32_t(uint8_t(in[i])) << 16 | uint32_t(uint8_t(in[i + 1])) << 8 | uint8_t(in[i + 2]);
        out += {t[v >> 18], t[(v >> 12) & 63], t[(v >> 6) & 63], t[v & 63]};
    }
    if (i + 1 == in.size()) {
        const uint32_t v = uint32_t(uint8_t(in[i])) << 16;
        out += {t[v >> 18], t[(v >> 12) & 63], '=', '='};
    } else if (i + 2 == in.size()) {
        const uint32_t v = uint32_t(uint8_t(in[i])) << 16 | uint32_t(uint8_t(in[i + 1])) << 8;
        out += {t[v >> 18], t[(v >> 12) & 63], t[(v >> 6) & 63], '='};
    }
    return out;
}

DataStore::DataStore(fs::path results_dir, fs::path out_dir)
    : results_dir_(std::move(results_dir)), out_dir_(std::move(out_dir)) {}

std::string DataStore::write(const std::string& meta_json, const std::string& packed, uint64_t content_hash) {
    const std::string key = fmt::format("{:016x}", content_hash);
    const fs::path file = out_dir_ / "data" / (key + ".js");
    std::error_code ec;
    if (!keys_.insert(key).second) return key; // same content: written by this report already
    if (fs::exists(file, ec))
        return key; // an earlier report into this folder wrote it  // same content: written by this report already
    fs::create_directories(file.parent_path(), ec);
    write_file_atomically(file, "iblcheckData(\"" + key + "\"," + meta_json + ",\"" + base64(packed) + "\");\n",
                          "the report's image data");
    return key;
}

namespace {
// Where results.json names a file: relative to its folder, and only inside it (empty otherwise:
// no file is read).
fs::path resolve(const fs::path& dir, const std::string& rel) { return inside_folder(dir, rel); }
} // namespace

namespace {
// An EXR's figures and its packed half floats: what image() writes, read and computed without
// touching the store (prepare() runs it on several threads). Nullopt for a missing or unreadable file.
std::optional<PreparedImage> prepare_image(const fs::path& src) {
    std::error_code ec;
    if (!fs::is_regular_file(src, ec)) return std::nullopt;
    try {
        LoadedImage li = read_image(src.string());
        cv::Mat m = li.pixels;
        if (li.file_channels == 1) cv::extractChannel(li.pixels, m, 0); // an error map
        const std::vector<uint16_t> half = to_half(m);
        PreparedImage p;
        FloatImageInfo& fi = p.info;
        fi.width = m.cols;
        fi.height = m.rows;
        fi.channels = m.channels();
        fi.auto_exposure = auto_exposure(m);
        double mn = 0, mx = 0;
        cv::minMaxLoc(m.reshape(1), &mn, &mx);
        fi.max = mx;
        {
            cv::Mat flat = m.reshape(1).clone();
            std::vector<float> v(flat.begin<float>(), flat.end<float>());
            const size_t k = size_t(std::ceil(0.99 * double(v.size()))) - 1;
            std::nth_element(v.begin(), v.begin() + long(k), v.end());
            fi.p99 = v[k];
        }
        Fnv1a64 h;
        h.update("f16");
        h.update(&fi.width, sizeof fi.width);
        h.update(&fi.height, sizeof fi.height);
        h.update(&fi.channels, sizeof fi.channels);
        h.update(half.data(), half.size() * 2);
        p.hash = h.value();
        p.meta = fmt::format("{{\"w\":{},\"h\":{},\"c\":{},\"enc\":\"f16\",\"auto\":{},\"max\":{},\"p99\":{}}}", fi.width,
                             fi.height, fi.channels, fi.auto_exposure, std::isfinite(fi.max) ? fi.max : 0.0,
                             std::isfinite(fi.p99) ? fi.p99 : 0.0);
        p.packed = pack_half(half);
        return p;
    } catch (const InputError&) {
        return std::nullopt; // an unreadable EXR: the page keeps the PNG
    }
}
} // namespace

void DataStore::prepare(const std::vector<std::string>& exr_rels, int threads) {
    std::vector<std::string> todo;
    for (const std::string& rel : exr_rels)
        if (!rel.empty() && !images_.count(rel) && !prepared_.count(rel) &&
            std::find(todo.begin(), todo.end(), rel) == todo.end())
            todo.push_back(rel);
    std::vector<std::optional<PreparedImage>> done(todo.size());
    parallel_for(int(todo.size()), threads,
                 [&](int i) { done[size_t(i)] = prepare_image(resolve(results_dir_, todo[size_t(i)])); });
    for (size_t i = 0; i < todo.size(); ++i) prepared_[todo[i]] = std::move(done[i]);
}

std::optional<FloatImageInfo> DataStore::image(const std::string& exr_rel) {
    if (exr_rel.empty()) return std::nullopt;
    if (auto it = images_.find(exr_rel); it != images_.end()) return it->second;
    std::optional<PreparedImage> p;
    if (auto it = prepared_.find(exr_rel); it != prepared_.end()) {
        p = std::move(it->second);
        prepared_.erase(it);
    } else {
        p = prepare_image(resolve(results_dir_, exr_rel));
    }
    std::optional<FloatImageInfo> info;
    if (p) {
        info = p->info;
        info->key = write(p->meta, p->packed, p->hash);
    }
    images_[exr_rel] = info;
    return info;
}

std::optional<std::string> DataStore::id_map(const std::string& png_rel, const nlohmann::json& spheres) {
    if (png_rel.empty()) return std::nullopt;
    if (auto it = maps_.find(png_rel); it != maps_.end()) return it->second;
    std::optional<std::string> key;
    std::error_code ec;
    const fs::path src = resolve(results_dir_, png_rel);
    if (fs::is_regular_file(src, ec)) {
        try {
            LoadedImage li = read_image(src.string());
            std::vector<uint8_t> ids(li.pixels.total());
            size_t i = 0;
            for (int y = 0; y < li.pixels.rows; ++y)
                for (int x = 0; x < li.pixels.cols; ++x)
                    ids[i++] = uint8_t(std::lround(li.pixels.at<cv::Vec3f>(y, x)[0] * 255.0f));
            Fnv1a64 h;
            h.update("u8");
            h.update(&li.pixels.cols, sizeof(int));
            h.update(&li.pixels.rows, sizeof(int));
            h.update(ids.data(), ids.size());
            const std::string sp = spheres.dump();
            h.update(sp);
            key = write(
                fmt::format("{{\"w\":{},\"h\":{},\"c\":1,\"enc\":\"u8\",\"spheres\":{}}}", li.pixels.cols, li.pixels.rows, sp),
                pack_bytes(ids), h.value());
        } catch (const InputError&) {
            key.reset();
        }
    }
    maps_[png_rel] = key;
    return key;
}

std::optional<std::string> DataStore::thumbnail(const std::string& exr_rel, int max_width, int max_height) {
    if (exr_rel.empty()) return std::nullopt;
    std::error_code ec;
    const fs::path src = resolve(results_dir_, exr_rel);
    if (!fs::is_regular_file(src, ec)) return std::nullopt;
    try {
        cv::Mat m = read_image(src.string()).pixels;
        const double ev = auto_exposure(m);
        const double s = std::min({1.0, double(max_width) / m.cols, double(max_height) / m.rows});
        cv::Mat small;
        if (s < 1)
            cv::resize(m, small, cv::Size(std::max(1, int(m.cols * s + 0.5)), std::max(1, int(m.rows * s + 0.5))), 0, 0,
                       cv::INTER_AREA);
        else
            small = m;
        small *= std::pow(2.0, ev);
        Fnv1a64 h;
        h.update("thumb");
        h.update(small.data, small.total() * small.elemSize());
        const std::string key = fmt::format("{:016x}", h.value());
        const fs::path file = out_dir_ / "thumbs" / (key + ".png");
        if (!fs::exists(file, ec)) {
            fs::create_directories(file.parent_path(), ec);
            write_png(file.string(), display_transform(small));
        }
        return "thumbs/" + key + ".png";
    } catch (const InputError&) {
        return std::nullopt;
    }
}

} // namespace iblcheck::report
