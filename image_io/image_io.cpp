#include "image_io/image_io.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <memory>
#include <vector>

#include <fmt/format.h>

#include "image_io/image_formats.h"
#include "kernel/errors.h"
#include "kernel/input_file.h"

namespace iblcheck {

namespace imagefile {
Format sniff_format(const std::string& path) {
    unsigned char magic[8] = {};
    if (FILE* f = std::fopen(path.c_str(), "rb")) {
        const size_t n = std::fread(magic, 1, sizeof magic, f);
        std::fclose(f);
        static const unsigned char kExr[4] = {0x76, 0x2f, 0x31, 0x01};
        static const unsigned char kPng[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
        if (n >= 4 && std::memcmp(magic, kExr, 4) == 0) return Format::exr;
        if (n >= 8 && std::memcmp(magic, kPng, 8) == 0) return Format::png;
    }
    return Format::other;
}

void check_claimed_size(const std::string& path, uint64_t width, uint64_t height, double stored_bits_per_pixel,
                        double max_ratio) {
    const uint64_t pixels = width * height; // each below 2^32: no overflow
    if (pixels > kMaxImagePixels)
        throw InputError(fmt::format("{}: header claims {}x{} pixels, more than iblcheck reads (at most {} pixels, e.g. "
                                     "16384x8192)",
                                     path, width, height, kMaxImagePixels));
    std::error_code ec;
    const uintmax_t file_bytes = std::filesystem::file_size(path, ec);
    if (max_ratio <= 0 || ec) return;
    const double data_bytes = double(pixels) * stored_bits_per_pixel / 8;
    if (data_bytes > double(file_bytes) * max_ratio)
        throw InputError(fmt::format("{}: header claims {}x{} pixels ({:.0f} bytes of pixel data), more than its {} bytes "
                                     "can hold at this format's largest compression ratio ({:g}:1): a corrupt or "
                                     "truncated file",
                                     path, width, height, data_bytes, file_bytes, max_ratio));
}

RawImage read_raw(const std::string& path, bool unassociated_alpha) {
    // Also "file not found", and a folder: "is a folder, not a regular file".
    require_regular_file(path);
    switch (sniff_format(path)) {
    case Format::exr:
        if (std::optional<RawImage> img = read_exr(path)) return std::move(*img);
        break; // a channel layout OpenImageIO orders its own way
    case Format::png: return read_png(path);
    case Format::other: break;
    }
    return read_with_oiio(path, unassociated_alpha);
}
} // namespace imagefile

LoadedImage read_image(const std::string& path) {
    // PNG's alpha is unassociated by definition: the colour is read as stored.
    imagefile::RawImage raw = imagefile::read_raw(path, true);
    const int nch = raw.channels;
    if (raw.width <= 0 || raw.height <= 0) throw InputError(fmt::format("{}: image has no pixels", path));
    if (nch < 1 || nch > 4) throw InputError(fmt::format("{}: unsupported channel count {} (expected 1-4)", path, nch));

    LoadedImage li;
    li.path = path;
    li.file_channels = nch;
    li.hdr = raw.hdr;
    // Grey (+alpha) -> RGB; RGBA -> RGB.
    li.pixels.create(raw.height, raw.width, CV_32FC3);
    const bool grey = nch <= 2;
    for (int y = 0; y < raw.height; ++y) {
        float* dst = li.pixels.ptr<float>(y);
        const float* src = raw.data.data() + size_t(y) * raw.width * nch;
        for (int x = 0; x < raw.width; ++x, src += nch, dst += 3) {
            if (grey) {
                dst[0] = dst[1] = dst[2] = src[0];
            } else {
                dst[0] = src[0], dst[1] = src[1], dst[2] = src[2];
            }
        }
    }
    return li;
}

namespace {
std::string lower_extension(const std::string& path) {
    std::string e = std::filesystem::path(path).extension().string();
    for (auto& c : e) c = char(std::tolower((unsigned char)c));
    return e;
}
} // namespace

void write_exr(const std::string& path, const cv::Mat& mat) {
    if (mat.depth() != CV_32F || (mat.channels() != 1 && mat.channels() != 3))
        throw InputError(fmt::format("{}: write_exr needs a 1- or 3-channel float image", path));
    cv::Mat c = mat.isContinuous() ? mat : mat.clone();
    // The format follows the file name, as it did when OpenImageIO chose the writer.
    if (lower_extension(path) == ".exr")
        imagefile::write_exr(path, c.cols, c.rows, c.channels(), c.ptr<float>());
    else
        imagefile::write_with_oiio(path, c.cols, c.rows, c.channels(), true, c.ptr<float>());
}

void write_exr_half(const std::string& path, const cv::Mat& mat) {
    if (mat.depth() != CV_32F || (mat.channels() != 1 && mat.channels() != 3))
        throw InputError(fmt::format("{}: write_exr_half needs a 1- or 3-channel float image", path));
    // Clamped before OpenEXR's conversion, which would turn values above 65504 into +Inf.
    cv::Mat c = cv::min(cv::max(mat, -65504.0f), 65504.0f);
    imagefile::write_exr(path, c.cols, c.rows, c.channels(), c.ptr<float>(), /*half=*/true);
}

void write_png(const std::string& path, const cv::Mat& mat) {
    if (mat.depth() != CV_32F || (mat.channels() != 1 && mat.channels() != 3))
        throw InputError(fmt::format("{}: write_png needs a 1- or 3-channel float image", path));
    std::vector<unsigned char> bytes(size_t(mat.total()) * mat.channels());
    size_t i = 0;
    for (int y = 0; y < mat.rows; ++y) {
        const float* p = mat.ptr<float>(y);
        for (int x = 0; x < mat.cols * mat.channels(); ++x) {
            float v = std::isnan(p[x]) ? 0.0f : std::min(std::max(p[x], 0.0f), 1.0f);
            bytes[i++] = (unsigned char)(v * 255.0f + 0.5f);
        }
    }
    if (lower_extension(path) == ".png")
        imagefile::write_png(path, mat.cols, mat.rows, mat.channels(), bytes.data());
    else
        imagefile::write_with_oiio(path, mat.cols, mat.rows, mat.channels(), false, bytes.data());
}

NonFinite find_non_finite(const cv::Mat& mat) {
    CV_Assert(mat.depth() == CV_32F);
    NonFinite nf;
    const int nch = mat.channels();
    for (int y = 0; y < mat.rows; ++y) {
        const float* p = mat.ptr<float>(y);
        for (int x = 0; x < mat.cols * nch; ++x) {
            if (!std::isfinite(p[x])) {
                if (nf.count == 0) nf.x = x / nch, nf.y = y;
                ++nf.count;
            }
        }
    }
    return nf;
}

std::string NonFinite::describe() const {
    return fmt::format("{} non-finite value(s) (NaN/Inf), first at x={}, y={}", count, x, y);
}

void check_finite(const cv::Mat& mat, const std::string& path) {
    if (NonFinite nf = find_non_finite(mat); nf.count) throw InputError(path + ": " + nf.describe());
}

size_t count_negative(const cv::Mat& mat) {
    CV_Assert(mat.depth() == CV_32F);
    size_t count = 0;
    for (int y = 0; y < mat.rows; ++y) {
        const float* p = mat.ptr<float>(y);
        for (int x = 0; x < mat.cols * mat.channels(); ++x) count += p[x] < 0.0f;
    }
    return count;
}

size_t clamp_negative(cv::Mat& mat) {
    CV_Assert(mat.depth() == CV_32F);
    size_t count = 0;
    for (int y = 0; y < mat.rows; ++y) {
        float* p = mat.ptr<float>(y);
        for (int x = 0; x < mat.cols * mat.channels(); ++x)
            if (p[x] < 0.0f) p[x] = 0.0f, ++count;
    }
    return count;
}

void check_same_size(const cv::Mat& a, const cv::Mat& b, const std::string& path_a, const std::string& path_b) {
    if (a.size() != b.size())
        throw InputError(fmt::format("{}: size {}x{} does not match {} ({}x{})", path_b, b.cols, b.rows, path_a, a.cols, a.rows));
}

} // namespace iblcheck
