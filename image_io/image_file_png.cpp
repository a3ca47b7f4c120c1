// PNG files through libpng (image_formats.h). libpng reports errors by longjmp, so the functions
// that call it hold only plain data between setjmp and the libpng calls (no C++ object may be
// skipped by the jump); buffers live in the caller.
#include <png.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <memory>

#include <fmt/format.h>

#include "image_io/image_formats.h"
#include "kernel/errors.h"

namespace iblcheck::imagefile {

namespace {

struct PngError {
    char message[256] = "";
};

void on_error(png_structp png, png_const_charp msg) {
    auto* err = static_cast<PngError*>(png_get_error_ptr(png));
    std::snprintf(err->message, sizeof err->message, "%s", msg);
    png_longjmp(png, 1);
}
void on_warning(png_structp, png_const_charp) {} // e.g. unknown chunks: not the harness's concern

struct FileCloser {
    void operator()(FILE* f) const { std::fclose(f); }
};
using File = std::unique_ptr<FILE, FileCloser>;

// Decoded header of a PNG after the transformations set up in png_header().
struct PngInfo {
    png_uint_32 width = 0, height = 0;
    int channels = 0, bit_depth = 0;
    int file_bits_per_pixel = 0; // as the file stores them, before the transformations
};

// Stage 1: read the header and set OpenImageIO's transformations. Returns false on a libpng error.
bool png_header(png_structp png, png_infop info, FILE* f, PngInfo* out) {
    if (setjmp(png_jmpbuf(png))) return false;
    png_init_io(png, f);
    png_read_info(png, info);
    const int color_type = png_get_color_type(png, info);
    const int depth = png_get_bit_depth(png, info);
    out->file_bits_per_pixel = depth * png_get_channels(png, info);
    // As OpenImageIO's PNG reader (png_pvt.h): palette -> RGB, grey 1/2/4 bits -> 8 bits, tRNS ->
    // alpha; 16-bit samples are big-endian in the file.
    if (color_type == PNG_COLOR_TYPE_PALETTE) png_set_palette_to_rgb(png);
    if (color_type == PNG_COLOR_TYPE_GRAY && depth < 8) png_set_expand_gray_1_2_4_to_8(png);
    if (png_get_valid(png, info, PNG_INFO_tRNS)) png_set_tRNS_to_alpha(png);
    if (depth == 16) png_set_swap(png);
    png_set_interlace_handling(png);
    png_read_update_info(png, info);
    out->width = png_get_image_width(png, info);
    out->height = png_get_image_height(png, info);
    out->channels = png_get_channels(png, info);
    out->bit_depth = png_get_bit_depth(png, info);
    return true;
}

// Stage 2: decode every row into `rows`. Returns false on a libpng error (truncated, bad CRC...).
bool png_pixels(png_structp png, png_infop info, png_bytepp rows) {
    if (setjmp(png_jmpbuf(png))) return false;
    png_read_image(png, rows);
    png_read_end(png, nullptr);
    return true;
}

bool png_write(png_structp png, png_infop info, FILE* f, int w, int h, int channels, png_bytepp rows) {
    if (setjmp(png_jmpbuf(png))) return false;
    png_init_io(png, f);
    png_set_IHDR(png, info, png_uint_32(w), png_uint_32(h), 8, channels == 1 ? PNG_COLOR_TYPE_GRAY : PNG_COLOR_TYPE_RGB,
                 PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
    // zlib level 1 (fastest): a ci run's report writes its PNGs (11 MB) in ~1.4 s less worker time
    // than at the default level 6, for 10 % more bytes (issue 33).
    png_set_compression_level(png, 1);
    png_write_info(png, info);
    png_write_image(png, rows);
    png_write_end(png, nullptr);
    return true;
}

} // namespace

RawImage read_png(const std::string& path) {
    File f(std::fopen(path.c_str(), "rb"));
    if (!f) throw InputError(fmt::format("{}: cannot read image (cannot open: {})", path, std::strerror(errno)));
    PngError err;
    png_structp png = png_create_read_struct(PNG_LIBPNG_VER_STRING, &err, on_error, on_warning);
    png_infop info = png ? png_create_info_struct(png) : nullptr;
    if (!png || !info) {
        png_destroy_read_struct(&png, &info, nullptr);
        throw InputError(fmt::format("{}: cannot read image (libpng: out of memory)", path));
    }
    struct Destroy {
        png_structp* p;
        png_infop* i;
        ~Destroy() { png_destroy_read_struct(p, i, nullptr); }
    } destroy{&png, &info};

    PngInfo hdr;
    if (!png_header(png, info, f.get(), &hdr)) throw InputError(fmt::format("{}: cannot read image ({})", path, err.message));
    // Before the rows are allocated: the pixels come out of IDAT's deflate stream.
    check_claimed_size(path, hdr.width, hdr.height, hdr.file_bits_per_pixel, kDeflateMaxRatio);
    RawImage img;
    img.width = int(hdr.width);
    img.height = int(hdr.height);
    img.channels = hdr.channels;
    img.hdr = false;
    img.reader = "libpng";
    const size_t bytes_per_sample = hdr.bit_depth == 16 ? 2 : 1;
    const size_t row_bytes = size_t(hdr.width) * hdr.channels * bytes_per_sample;
    std::vector<unsigned char> raw(row_bytes * hdr.height);
    std::vector<png_bytep> rows(hdr.height);
    for (size_t y = 0; y < hdr.height; ++y) rows[y] = raw.data() + y * row_bytes;
    if (!png_pixels(png, info, rows.data()))
        throw InputError(fmt::format("{}: corrupt or truncated image data ({})", path, err.message));

    // Integer codes as k / (2^bits - 1): exactly k/255.0f for 8 bits (what the FLIP tool reads).
    const size_t n = size_t(hdr.width) * hdr.height * hdr.channels;
    img.data.resize(n);
    if (bytes_per_sample == 1) {
        for (size_t i = 0; i < n; ++i) img.data[i] = float(raw[i]) / 255.0f;
    } else {
        const auto* p16 = reinterpret_cast<const unsigned short*>(raw.data());
        for (size_t i = 0; i < n; ++i) img.data[i] = float(p16[i]) / 65535.0f;
    }
    return img;
}

void write_png(const std::string& path, int width, int height, int channels, const uint8_t* data) {
    File f(std::fopen(path.c_str(), "wb"));
    if (!f) throw InputError(fmt::format("{}: cannot open for writing ({})", path, std::strerror(errno)));
    PngError err;
    png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, &err, on_error, on_warning);
    png_infop info = png ? png_create_info_struct(png) : nullptr;
    if (!png || !info) {
        png_destroy_write_struct(&png, &info);
        throw InputError(fmt::format("{}: cannot open for writing (libpng: out of memory)", path));
    }
    std::vector<png_bytep> rows(static_cast<size_t>(height));
    for (int y = 0; y < height; ++y) rows[size_t(y)] = const_cast<png_bytep>(data + size_t(y) * width * channels);
    const bool ok = png_write(png, info, f.get(), width, height, channels, rows.data());
    png_destroy_write_struct(&png, &info);
    if (!ok) throw InputError(fmt::format("{}: write failed ({})", path, err.message));
    if (std::fflush(f.get()) != 0 || std::ferror(f.get()))
        throw InputError(fmt::format("{}: write failed ({})", path, std::strerror(errno)));
}

} // namespace iblcheck::imagefile
