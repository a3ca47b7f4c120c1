// The image file codecs (image_io/image_formats.h): OpenEXR and PNG are read without OpenImageIO,
// and must return exactly what OpenImageIO returns (the plugin, libiblcheck_oiio.so, is the
// oracle) on files written by OpenImageIO itself in every layout the harness may meet; other
// formats go through the plugin; reading EXR/PNG never loads it.
#include <OpenImageIO/imageio.h>
#include <gtest/gtest.h>
#include <png.h>

#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <random>

#include "image_io/image_formats.h"
#include "image_io/image_io.h"
#include "kernel/errors.h"
#include "tests/test_support.h"

namespace fs = std::filesystem;
using namespace iblcheck;

// Its own namespace: the test programs of one group compile as unity batches (tests/CMakeLists.txt).
namespace test_image_formats {

namespace {

class ImageFormats : public ::testing::Test {
  protected:
    static void SetUpTestSuite() { dir_ = testutil::temp_dir("image_formats"); }
    static void TearDownTestSuite() { fs::remove_all(dir_); }
    static std::string path(const std::string& name) { return (dir_ / name).string(); }
    static fs::path dir_;
};
fs::path ImageFormats::dir_;

// Writes a file with OpenImageIO: w x h x nch values of `type` from `values` (as floats in [0,1]
// for integer types), with extra spec attributes.
void write_oiio(const std::string& file, int w, int h, int nch, OIIO::TypeDesc type, const std::vector<float>& values,
                const std::vector<std::pair<std::string, std::string>>& attrs = {},
                const std::vector<std::string>& channel_names = {}) {
    auto out = OIIO::ImageOutput::create(file);
    ASSERT_TRUE(out) << OIIO::geterror();
    OIIO::ImageSpec spec(w, h, nch, type);
    for (const auto& [k, v] : attrs) {
        if (k == "tile")
            spec.tile_width = spec.tile_height = std::stoi(v);
        else if (k == "x")
            spec.x = std::stoi(v);
        else if (k == "y")
            spec.y = std::stoi(v);
        else if (k == "png:bitdepth" || k == "oiio:BitsPerSample")
            spec.attribute(k, std::stoi(v));
        else
            spec.attribute(k, v);
    }
    if (!channel_names.empty()) spec.channelnames = channel_names;
    if (nch == 2 || nch == 4) spec.alpha_channel = nch - 1;
    ASSERT_TRUE(out->open(file, spec)) << out->geterror();
    ASSERT_TRUE(out->write_image(OIIO::TypeDesc::FLOAT, values.data())) << out->geterror();
    out->close();
}

std::vector<float> ramp(int w, int h, int nch, float scale, unsigned seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    std::vector<float> v(size_t(w) * h * nch);
    for (auto& x : v) x = u(rng) * scale;
    return v;
}

void expect_same_as_oiio(const std::string& file, const std::string& native_reader) {
    const imagefile::RawImage native = imagefile::read_raw(file, true);
    const imagefile::RawImage oiio = imagefile::read_with_oiio(file, true);
    EXPECT_EQ(native.reader, native_reader) << file;
    EXPECT_EQ(oiio.reader, "openimageio");
    ASSERT_EQ(native.width, oiio.width) << file;
    ASSERT_EQ(native.height, oiio.height) << file;
    ASSERT_EQ(native.channels, oiio.channels) << file;
    EXPECT_EQ(native.hdr, oiio.hdr) << file;
    ASSERT_EQ(native.data.size(), oiio.data.size()) << file;
    EXPECT_EQ(std::memcmp(native.data.data(), oiio.data.data(), native.data.size() * sizeof(float)), 0)
        << file << ": pixel values differ from OpenImageIO's";
}

// A palette or grey PNG of `depth` bits per sample from sample values `v` (row-major, one per
// pixel), optionally with a tRNS chunk (palette: per-entry alpha; grey: one transparent value).
bool png_body(png_structp png, png_infop info, FILE* f, int w, int h, int depth, bool palette, bool trns, png_bytepp rows) {
    if (setjmp(png_jmpbuf(png))) return false;
    png_init_io(png, f);
    png_set_IHDR(png, info, png_uint_32(w), png_uint_32(h), depth, palette ? PNG_COLOR_TYPE_PALETTE : PNG_COLOR_TYPE_GRAY,
                 PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
    png_color pal[256];
    png_byte alpha[256];
    for (int i = 0; i < 256; ++i) {
        pal[i] = {png_byte(i * 37), png_byte(255 - i * 11), png_byte(i * 101)};
        alpha[i] = png_byte(255 - i * 29);
    }
    png_color_16 key{};
    key.gray = png_uint_16(1);
    if (palette) png_set_PLTE(png, info, pal, 1 << depth);
    if (trns) {
        if (palette)
            png_set_tRNS(png, info, alpha, 1 << depth, nullptr);
        else
            png_set_tRNS(png, info, nullptr, 0, &key);
    }
    png_write_info(png, info);
    png_write_image(png, rows);
    png_write_end(png, nullptr);
    return true;
}

bool write_low_bit_png(const std::string& file, int w, int h, int depth, bool palette, bool trns,
                       const std::vector<unsigned char>& v) {
    std::vector<std::vector<png_byte>> packed(size_t(h), std::vector<png_byte>(size_t(w * depth + 7) / 8, 0));
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const int bit = x * depth;
            packed[size_t(y)][size_t(bit / 8)] |= png_byte(v[size_t(y) * w + x] << (8 - depth - bit % 8));
        }
    std::vector<png_bytep> rows;
    for (auto& r : packed) rows.push_back(r.data());
    FILE* f = std::fopen(file.c_str(), "wb");
    if (!f) return false;
    png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, nullptr, nullptr, nullptr);
    png_infop info = png_create_info_struct(png);
    const bool ok = png_body(png, info, f, w, h, depth, palette, trns, rows.data());
    png_destroy_write_struct(&png, &info);
    std::fclose(f);
    return ok;
}

} // namespace

TEST_F(ImageFormats, PngAndExrAreReadWithoutOpenImageIO) {
    // First in this file: nothing has loaded the plugin yet.
    write_oiio(path("first.png"), 5, 4, 3, OIIO::TypeDesc::UINT8, ramp(5, 4, 3, 1.0f, 1));
    write_oiio(path("first.exr"), 5, 4, 3, OIIO::TypeDesc::HALF, ramp(5, 4, 3, 8.0f, 2));
    ASSERT_FALSE(imagefile::oiio_plugin_loaded());
    EXPECT_EQ(read_image(path("first.png")).pixels.cols, 5);
    EXPECT_EQ(read_image(path("first.exr")).pixels.rows, 4);
    write_png(path("mine.png"), read_image(path("first.png")).pixels);
    write_exr(path("mine.exr"), read_image(path("first.exr")).pixels);
    EXPECT_FALSE(imagefile::oiio_plugin_loaded()) << "reading or writing PNG/EXR loaded OpenImageIO";
}

TEST_F(ImageFormats, PngLayoutsMatchOpenImageIO) {
    const int w = 13, h = 7;
    for (int nch : {1, 2, 3, 4})
        for (auto type : {OIIO::TypeDesc::UINT8, OIIO::TypeDesc::UINT16}) {
            const std::string f =
                path("c" + std::to_string(nch) + "_" + std::to_string(int(OIIO::TypeDesc(type).size())) + ".png");
            write_oiio(f, w, h, nch, type, ramp(w, h, nch, 1.0f, unsigned(nch)));
            expect_same_as_oiio(f, "libpng");
        }
    // Interlaced (Adam7).
    write_oiio(path("interlaced.png"), w, h, 3, OIIO::TypeDesc::UINT8, ramp(w, h, 3, 1.0f, 9),
               {{"png:interlaced", "1"}, {"oiio:interlaced", "1"}});
    expect_same_as_oiio(path("interlaced.png"), "libpng");
}

TEST_F(ImageFormats, PalettedAndLowBitPngMatchOpenImageIO) {
    // Layouts OpenImageIO does not write: palette (with and without a tRNS chunk) and 1/2/4-bit grey
    // (with a tRNS grey key too), written with libpng here.
    std::mt19937 rng(60);
    for (int depth : {1, 2, 4, 8}) {
        const int w = 19, h = 5, maxv = (1 << depth) - 1;
        std::vector<unsigned char> idx(size_t(w) * h);
        for (auto& v : idx) v = (unsigned char)(rng() % unsigned(maxv + 1));
        for (bool trns : {false, true}) {
            const std::string tag = std::to_string(depth) + (trns ? "_trns" : "");
            ASSERT_TRUE(write_low_bit_png(path("pal" + tag + ".png"), w, h, depth, true, trns, idx));
            expect_same_as_oiio(path("pal" + tag + ".png"), "libpng");
            ASSERT_TRUE(write_low_bit_png(path("grey" + tag + ".png"), w, h, depth, false, trns, idx));
            expect_same_as_oiio(path("grey" + tag + ".png"), "libpng");
        }
    }
}

TEST_F(ImageFormats, ExrLayoutsMatchOpenImageIO) {
    const int w = 11, h = 6;
    for (int nch : {1, 2, 3, 4})
        for (auto type : {OIIO::TypeDesc::HALF, OIIO::TypeDesc::FLOAT}) {
            const std::string f =
                path("c" + std::to_string(nch) + "_" + std::to_string(int(OIIO::TypeDesc(type).size())) + ".exr");
            // Two channels: grey + alpha (OpenImageIO would name them R, G by default).
            write_oiio(f, w, h, nch, type, ramp(w, h, nch, 100.0f, unsigned(nch) + 10), {},
                       nch == 2 ? std::vector<std::string>{"Y", "A"} : std::vector<std::string>{});
            expect_same_as_oiio(f, "openexr");
        }
    // Tiled, with a data window that does not start at 0,0, and another compression.
    write_oiio(path("tiled.exr"), w, h, 3, OIIO::TypeDesc::HALF, ramp(w, h, 3, 5.0f, 20),
               {{"tile", "4"}, {"x", "3"}, {"y", "-2"}, {"compression", "piz"}});
    expect_same_as_oiio(path("tiled.exr"), "openexr");
}

TEST_F(ImageFormats, OtherExrChannelLayoutsGoThroughOpenImageIO) {
    // Layers, or channels that are not R,G,B(,A) / Y(,A): OpenImageIO orders them its own way.
    write_oiio(path("layers.exr"), 4, 4, 3, OIIO::TypeDesc::FLOAT, ramp(4, 4, 3, 1.0f, 30), {},
               {"diffuse.R", "diffuse.G", "diffuse.B"});
    EXPECT_EQ(imagefile::read_raw(path("layers.exr"), true).reader, "openimageio");
    write_oiio(path("rg.exr"), 3, 2, 2, OIIO::TypeDesc::HALF, ramp(3, 2, 2, 1.0f, 32));
    expect_same_as_oiio(path("rg.exr"), "openimageio");
    write_oiio(path("five.exr"), 2, 2, 5, OIIO::TypeDesc::FLOAT, ramp(2, 2, 5, 1.0f, 31));
    EXPECT_EQ(imagefile::read_raw(path("five.exr"), true).channels, 5);
}

TEST_F(ImageFormats, OtherFormatsGoThroughThePlugin) {
    write_oiio(path("a.hdr"), 8, 4, 3, OIIO::TypeDesc::FLOAT, ramp(8, 4, 3, 50.0f, 40));
    const imagefile::RawImage hdr = imagefile::read_raw(path("a.hdr"), true);
    EXPECT_EQ(hdr.reader, "openimageio");
    EXPECT_TRUE(hdr.hdr);
    EXPECT_EQ(hdr.width, 8);
    const LoadedImage li = read_image(path("a.hdr"));
    EXPECT_TRUE(li.hdr);
    // Writing a format that is neither EXR nor PNG also goes through the plugin (by file name).
    write_exr(path("b.tif"), li.pixels);
    const imagefile::RawImage tif = imagefile::read_raw(path("b.tif"), true);
    EXPECT_EQ(tif.reader, "openimageio");
    EXPECT_EQ(std::memcmp(tif.data.data(), li.pixels.ptr<float>(), tif.data.size() * sizeof(float)), 0);
}

TEST_F(ImageFormats, WrittenFilesAreWhatOpenImageIOWrote) {
    // Channel names, pixel type and compression as OpenImageIO's writer chose them.
    cv::Mat rgb(3, 4, CV_32FC3), grey(3, 4, CV_32F);
    for (int i = 0; i < 36; ++i) rgb.ptr<float>()[i] = 0.37f * float(i);
    for (int i = 0; i < 12; ++i) grey.ptr<float>()[i] = 0.5f + float(i);
    write_exr(path("rgb.exr"), rgb);
    write_exr(path("grey.exr"), grey);
    auto spec_of = [](const std::string& f) {
        auto in = OIIO::ImageInput::open(f);
        EXPECT_TRUE(in);
        return in ? in->spec() : OIIO::ImageSpec();
    };
    const OIIO::ImageSpec s3 = spec_of(path("rgb.exr")), s1 = spec_of(path("grey.exr"));
    EXPECT_EQ(s3.channelnames, (std::vector<std::string>{"R", "G", "B"}));
    EXPECT_EQ(s1.channelnames, (std::vector<std::string>{"Y"}));
    EXPECT_EQ(s3.format, OIIO::TypeDesc::FLOAT);
    EXPECT_EQ(s3.get_string_attribute("compression"), "zip");
    expect_same_as_oiio(path("rgb.exr"), "openexr");
    write_png(path("rgb.png"), rgb / 20.0);
    const OIIO::ImageSpec sp = spec_of(path("rgb.png"));
    EXPECT_EQ(sp.nchannels, 3);
    EXPECT_EQ(sp.format, OIIO::TypeDesc::UINT8);
    expect_same_as_oiio(path("rgb.png"), "libpng");
}

// Issue 33: the report's PNGs took ~1.4 s of a warm ci run's worker time more at zlib's default
// level 6; they are written at level 1 (fastest), which the zlib header of the first IDAT chunk
// records (FLEVEL 0), and read back with the same pixels.
TEST_F(ImageFormats, PngsAreWrittenAtZlibsFastestLevelWithTheSamePixels) {
    cv::Mat rgb(48, 64, CV_32FC3);
    for (int i = 0; i < 48 * 64 * 3; ++i) rgb.ptr<float>()[i] = float((i * 37) % 256) / 255.0f;
    write_png(path("fast.png"), rgb);
    std::ifstream f(path("fast.png"), std::ios::binary);
    const std::string bytes((std::istreambuf_iterator<char>(f)), {});
    const size_t idat = bytes.find("IDAT");
    ASSERT_NE(idat, std::string::npos);
    ASSERT_GT(bytes.size(), idat + 6);
    const auto cmf = uint8_t(bytes[idat + 4]), flg = uint8_t(bytes[idat + 5]);
    EXPECT_EQ(cmf & 0x0f, 8);           // deflate
    EXPECT_EQ(flg >> 6, 0) << "FLEVEL"; // 0: fastest (level 1); 2 was the default level 6
    const LoadedImage back = read_image(path("fast.png"));
    ASSERT_EQ(back.pixels.size(), rgb.size());
    for (int y = 0; y < rgb.rows; ++y)
        for (int x = 0; x < rgb.cols; ++x)
            for (int c = 0; c < 3; ++c)
                ASSERT_EQ(back.pixels.at<cv::Vec3f>(y, x)[c], rgb.at<cv::Vec3f>(y, x)[c]) << x << "," << y;
}

TEST_F(ImageFormats, BadFilesNameThePathAndTheProblem) {
    auto message = [](const std::string& f) {
        try {
            read_image(f);
        } catch (const InputError& e) {
            return std::string(e.what());
        }
        return std::string("no exception");
    };
    testutil::write_file(path("junk.png"), "\x89PNG\r\n\x1a\n but then nothing a PNG should hold");
    testutil::write_file(path("junk.exr"), std::string("\x76\x2f\x31\x01", 4) + "garbage after the magic number");
    EXPECT_EQ(message(path("junk.png")).rfind(path("junk.png") + ": cannot read image (", 0), 0u) << message(path("junk.png"));
    EXPECT_EQ(message(path("junk.exr")).rfind(path("junk.exr") + ": cannot read image (", 0), 0u) << message(path("junk.exr"));
    // Truncated pixel data: the header reads, the pixels do not.
    write_oiio(path("whole.png"), 64, 64, 3, OIIO::TypeDesc::UINT8, ramp(64, 64, 3, 1.0f, 50));
    write_oiio(path("whole.exr"), 64, 64, 3, OIIO::TypeDesc::FLOAT, ramp(64, 64, 3, 1.0f, 51));
    for (const std::string name : {"whole.png", "whole.exr"}) {
        const std::string bytes = testutil::read_text(path(name));
        const std::string cut = "cut_" + name;
        std::ofstream(path(cut), std::ios::binary) << bytes.substr(0, bytes.size() / 2);
        EXPECT_EQ(message(path(cut)).rfind(path(cut) + ": ", 0), 0u) << message(path(cut));
        EXPECT_NE(message(path(cut)), "no exception");
    }
    EXPECT_EQ(message(path("none.png")), path("none.png") + ": file not found");
}
} // namespace test_image_formats
