#include "metrics/image_io.h"

#include <cmath>
#include <filesystem>
#include <memory>
#include <vector>

#include <OpenImageIO/imageio.h>
#include <fmt/format.h>

#include "harness/common/errors.h"

namespace iblcheck {

namespace {
bool is_hdr_format(const OIIO::ImageSpec& spec, const std::string& format_name) {
    if (format_name == "openexr" || format_name == "hdr") return true;
    return spec.format.basetype == OIIO::TypeDesc::HALF ||
           spec.format.basetype == OIIO::TypeDesc::FLOAT ||
           spec.format.basetype == OIIO::TypeDesc::DOUBLE;
}
} // namespace

LoadedImage read_image(const std::string& path) {
    std::error_code ec;
    if (!std::filesystem::exists(path, ec))
        throw InputError(fmt::format("{}: file not found", path));
    if (std::filesystem::is_directory(path, ec))
        throw InputError(fmt::format("{}: is a directory, not an image", path));
    // OpenImageIO premultiplies colour by alpha on read unless told the file's alpha is
    // unassociated, which PNG's is by definition: read the colour as stored.
    OIIO::ImageSpec config;
    config.attribute("oiio:UnassociatedAlpha", 1);
    auto in = OIIO::ImageInput::open(path, &config);
    if (!in) {
        std::string why = OIIO::geterror();
        throw InputError(fmt::format("{}: cannot read image ({})", path,
                                     why.empty() ? "unknown format or corrupt file" : why));
    }
    const OIIO::ImageSpec spec = in->spec();
    const int nch = spec.nchannels;
    if (spec.width <= 0 || spec.height <= 0)
        throw InputError(fmt::format("{}: image has no pixels", path));
    if (nch < 1 || nch > 4)
        throw InputError(fmt::format("{}: unsupported channel count {} (expected 1-4)", path, nch));

    LoadedImage li;
    li.path = path;
    li.file_channels = nch;
    li.hdr = is_hdr_format(spec, in->format_name());
    const size_t npix = size_t(spec.width) * spec.height;
    std::vector<float> data(npix * nch);
    bool ok;
    if (li.hdr) {
        ok = in->read_image(0, 0, 0, nch, OIIO::TypeDesc::FLOAT, data.data());
    } else if (spec.format.basetype == OIIO::TypeDesc::UINT8) {
        // Divide by 255 ourselves so values are exactly k/255.0f (matches the FLIP tool).
        std::vector<unsigned char> raw(npix * nch);
        ok = in->read_image(0, 0, 0, nch, OIIO::TypeDesc::UINT8, raw.data());
        for (size_t i = 0; i < raw.size(); ++i) data[i] = float(raw[i]) / 255.0f;
    } else {
        std::vector<unsigned short> raw(npix * nch);
        ok = in->read_image(0, 0, 0, nch, OIIO::TypeDesc::UINT16, raw.data());
        for (size_t i = 0; i < raw.size(); ++i) data[i] = float(raw[i]) / 65535.0f;
    }
    if (!ok) {
        std::string why = in->geterror();
        throw InputError(fmt::format("{}: corrupt or truncated image data ({})", path,
                                     why.empty() ? "read failed" : why));
    }
    in->close();

    // Grey (+alpha) -> RGB; RGBA -> RGB.
    li.pixels.create(spec.height, spec.width, CV_32FC3);
    const bool grey = nch <= 2;
    for (int y = 0; y < spec.height; ++y) {
        float* dst = li.pixels.ptr<float>(y);
        const float* src = data.data() + size_t(y) * spec.width * nch;
        for (int x = 0; x < spec.width; ++x, src += nch, dst += 3) {
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
void write_with_oiio(const std::string& path, const cv::Mat& mat, OIIO::TypeDesc type,
                     const void* data) {
    const int nch = mat.channels();
    auto out = OIIO::ImageOutput::create(path);
    if (!out) throw InputError(fmt::format("{}: cannot create image writer ({})", path, OIIO::geterror()));
    OIIO::ImageSpec spec(mat.cols, mat.rows, nch, type);
    if (!out->open(path, spec))
        throw InputError(fmt::format("{}: cannot open for writing ({})", path, out->geterror()));
    if (!out->write_image(type, data))
        throw InputError(fmt::format("{}: write failed ({})", path, out->geterror()));
    out->close();
}
} // namespace

void write_exr(const std::string& path, const cv::Mat& mat) {
    if (mat.depth() != CV_32F || (mat.channels() != 1 && mat.channels() != 3))
        throw InputError(fmt::format("{}: write_exr needs a 1- or 3-channel float image", path));
    cv::Mat c = mat.isContinuous() ? mat : mat.clone();
    write_with_oiio(path, c, OIIO::TypeDesc::FLOAT, c.ptr<float>());
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
    write_with_oiio(path, mat, OIIO::TypeDesc::UINT8, bytes.data());
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

void check_same_size(const cv::Mat& a, const cv::Mat& b, const std::string& path_a,
                     const std::string& path_b) {
    if (a.size() != b.size())
        throw InputError(fmt::format("{}: size {}x{} does not match {} ({}x{})", path_b, b.cols,
                                     b.rows, path_a, a.cols, a.rows));
}

} // namespace iblcheck
