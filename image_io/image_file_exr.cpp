// OpenEXR files through the OpenEXR library itself (image_formats.h).
#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfInputFile.h>
#include <ImfOutputFile.h>
#include <half.h>

#include <algorithm>
#include <cstdint>
#include <exception>
#include <memory>
#include <vector>

#include <fmt/format.h>

#include "image_io/image_formats.h"
#include "kernel/errors.h"

namespace iblcheck::imagefile {

namespace {
// OpenEXR reports problems as exceptions (Iex); the harness's messages name the file first.
std::unique_ptr<Imf::InputFile> open_exr(const std::string& path) {
    try {
        return std::make_unique<Imf::InputFile>(path.c_str());
    } catch (const std::exception& e) {
        throw InputError(fmt::format("{}: cannot read image ({})", path, e.what()));
    }
}

// The largest ratio of pixel data to file bytes each compression reaches; 0 where none is known.
double max_ratio(Imf::Compression c) {
    switch (c) {
    case Imf::NO_COMPRESSION: return 1;
    case Imf::RLE_COMPRESSION: return 64; // a run of at most 128 bytes in 2
    case Imf::ZIPS_COMPRESSION:
    case Imf::ZIP_COMPRESSION:
    // PIZ: Huffman codes with 8-bit run lengths, at most 256 values of 16 bits in 10 bits (410:1).
    case Imf::PIZ_COMPRESSION: return kDeflateMaxRatio;
    case Imf::PXR24_COMPRESSION: return kDeflateMaxRatio * 4 / 3; // 32-bit floats kept in 24 bits, then deflate
    case Imf::B44_COMPRESSION:
    case Imf::B44A_COMPRESSION: return 11; // a flat 4x4 block of halves (32 bytes) in 3 bytes
    default: return 0;                     // DWAA/DWAB: a DCT, then Huffman and deflate
    }
}

// The header's data window against the file's size, before the pixels are allocated.
void check_claim(const std::string& path, const Imf::Header& h) {
    double bits = 0; // per pixel, as stored before compression
    for (auto it = h.channels().begin(); it != h.channels().end(); ++it) {
        const Imf::Channel& ch = it.channel();
        bits += (ch.type == Imf::HALF ? 16.0 : 32.0) / (double(std::max(ch.xSampling, 1)) * std::max(ch.ySampling, 1));
    }
    const Imath::Box2i dw = h.dataWindow();
    const int64_t w = int64_t(dw.max.x) - dw.min.x + 1, hgt = int64_t(dw.max.y) - dw.min.y + 1;
    if (w > 0 && hgt > 0) check_claimed_size(path, uint64_t(w), uint64_t(hgt), bits, max_ratio(h.compression()));
}
} // namespace

std::optional<RawImage> read_exr(const std::string& path) {
    const std::unique_ptr<Imf::InputFile> file = open_exr(path);
    Imf::InputFile& in = *file;
    try {
        const Imf::Header& h = in.header();
        check_claim(path, h);
        const Imath::Box2i dw = h.dataWindow();
        const Imf::ChannelList& cl = h.channels();
        std::vector<std::string> names;
        for (auto it = cl.begin(); it != cl.end(); ++it) {
            // Subsampled channels (luminance/chroma files) and integer channels: OpenImageIO's job.
            if (it.channel().xSampling != 1 || it.channel().ySampling != 1 || it.channel().type == Imf::UINT) return std::nullopt;
            names.push_back(it.name());
        }
        // OpenEXR stores channel names sorted (B, G, R); the harness reads them as OpenImageIO
        // orders them: R, G, B, then A; Y, then A.
        std::vector<std::string> order;
        auto has = [&](const char* n) { return cl.findChannel(n) != nullptr; };
        if (names.size() == 3 && has("R") && has("G") && has("B"))
            order = {"R", "G", "B"};
        else if (names.size() == 4 && has("R") && has("G") && has("B") && has("A"))
            order = {"R", "G", "B", "A"};
        else if (names.size() == 1 && has("Y"))
            order = {"Y"};
        else if (names.size() == 2 && has("Y") && has("A"))
            order = {"Y", "A"};
        else
            return std::nullopt;

        RawImage img;
        img.width = dw.max.x - dw.min.x + 1;
        img.height = dw.max.y - dw.min.y + 1;
        img.channels = int(order.size());
        img.hdr = true;
        img.reader = "openexr";
        if (img.width <= 0 || img.height <= 0) return img;
        img.data.resize(size_t(img.width) * img.height * img.channels);
        const size_t xs = sizeof(float) * img.channels, ys = xs * img.width;
        Imf::FrameBuffer fb;
        for (int c = 0; c < img.channels; ++c)
            fb.insert(order[size_t(c)], Imf::Slice::Make(Imf::FLOAT, img.data.data() + c, dw, xs, ys));
        in.setFrameBuffer(fb);
        in.readPixels(dw.min.y, dw.max.y);
        return img;
    } catch (const InputError&) {
        throw;
    } catch (const std::exception& e) {
        throw InputError(fmt::format("{}: corrupt or truncated image data ({})", path, e.what()));
    }
}

void write_exr(const std::string& path, int width, int height, int channels, const float* data, bool half) {
    static const char* const kRgb[] = {"R", "G", "B"};
    static const char* const kY[] = {"Y"};
    const char* const* names = channels == 1 ? kY : kRgb;
    Imf::Header h(width, height);
    h.compression() = Imf::ZIP_COMPRESSION;
    for (int c = 0; c < channels; ++c) h.channels().insert(names[c], Imf::Channel(half ? Imf::HALF : Imf::FLOAT));
    std::unique_ptr<Imf::OutputFile> file;
    try {
        file = std::make_unique<Imf::OutputFile>(path.c_str(), h);
    } catch (const std::exception& e) {
        throw InputError(fmt::format("{}: cannot open for writing ({})", path, e.what()));
    }
    try {
        Imf::OutputFile& out = *file;
        Imf::FrameBuffer fb;
        // OpenEXR converts pixel types when reading but not when writing: halves are rounded here
        // (to nearest, Imath's conversion, as OpenImageIO did).
        std::vector<Imath::half> halves;
        if (half) halves.assign(data, data + size_t(width) * height * channels);
        const size_t elem = half ? sizeof(Imath::half) : sizeof(float);
        const size_t xs = elem * channels, ys = xs * width;
        for (int c = 0; c < channels; ++c) {
            char* base = half ? (char*)(halves.data() + c) : (char*)(data + c);
            fb.insert(names[c], Imf::Slice(half ? Imf::HALF : Imf::FLOAT, base, xs, ys));
        }
        out.setFrameBuffer(fb);
        out.writePixels(height);
    } catch (const std::exception& e) {
        throw InputError(fmt::format("{}: write failed ({})", path, e.what()));
    }
}

} // namespace iblcheck::imagefile
