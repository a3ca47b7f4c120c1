// Image file codecs behind image_io/image_io.h. The formats the harness reads and writes all the
// time (OpenEXR, PNG) are decoded here with their reference libraries (OpenEXR, libpng), which load
// in about a millisecond; every other format goes through OpenImageIO in a plugin
// (libiblcheck_oiio.so) that is loaded on first use, because Debian's OpenImageIO links ~250
// shared libraries (ffmpeg, gdal, ...) and costs ~0.1-0.3 s and 130 MiB to load (issue 20).
// The native readers return exactly what OpenImageIO returned before (tests/test_image_formats.cpp
// compares them file by file with the plugin).
#pragma once
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace iblcheck::imagefile {

// Decoded pixels before the harness's conventions (RGB, alpha dropped) are applied.
struct RawImage {
    int width = 0, height = 0, channels = 0;
    bool hdr = false;        // float data (EXR, Radiance HDR, float TIFF); false: integer codes
    std::vector<float> data; // row-major, channels interleaved; integer codes as k / (2^bits - 1)
    std::string reader;      // "openexr", "libpng" or "openimageio" (tests check which one ran)
};

// Any image file: OpenEXR (known channel layouts) and PNG natively, everything else through the
// plugin. Throws InputError "<path>: file not found" / "is a directory" / "cannot read image (...)".
RawImage read_raw(const std::string& path, bool unassociated_alpha);

// The most pixels iblcheck reads from one image file: 2^27 (16384 x 8192, the largest HDRIs
// published), 1.5 GiB as float RGB. A header that claims more is refused before anything is
// allocated for it.
inline constexpr uint64_t kMaxImagePixels = uint64_t(1) << 27;

// A header's claim, checked before the reader allocates for it: throws InputError naming the file
// and the claimed size when width x height exceeds kMaxImagePixels, or when the pixel data
// (`stored_bits_per_pixel` each, as the format stores them before compression) is more than the
// file's bytes can expand to at the compression's largest ratio `max_ratio` (0: no bound is known,
// only the maximum applies). A truncated or forged header then costs nothing to refuse.
void check_claimed_size(const std::string& path, uint64_t width, uint64_t height, double stored_bits_per_pixel, double max_ratio);
// Deflate's largest expansion (a 258-byte match in two 1-bit codes): PNG's and OpenEXR ZIP's bound.
inline constexpr double kDeflateMaxRatio = 1032;

enum class Format { exr, png, other };
// By the file's first bytes (the magic numbers), not its name.
Format sniff_format(const std::string& path);

// Reads the first part of an OpenEXR file whose channels are {R,G,B}, {R,G,B,A}, {Y} or {Y,A}
// (half or float), in that order. Any other channel layout returns nullopt (the caller asks
// OpenImageIO, which orders channels its own way). Throws InputError "<path>: ..." on a bad file.
std::optional<RawImage> read_exr(const std::string& path);

// Reads any PNG as OpenImageIO does: palette -> RGB, grey below 8 bits -> 8 bits, a tRNS chunk ->
// an alpha channel, colour as stored (unassociated alpha, no gamma). Throws InputError.
RawImage read_png(const std::string& path);

// OpenImageIO through the plugin (loaded on first call). unassociated_alpha: read colour as stored
// rather than multiplied by alpha. Throws InputError (also when the plugin cannot be loaded).
RawImage read_with_oiio(const std::string& path, bool unassociated_alpha);

// OpenEXR, ZIP compression, channels R,G,B (3) or Y (1), as OpenImageIO wrote them; stored as float,
// or as half (`half`: OpenEXR converts, values beyond ±65504 become ±Inf, so callers clamp first).
void write_exr(const std::string& path, int width, int height, int channels, const float* data, bool half = false);
// 8-bit PNG, RGB (3) or grey (1).
void write_png(const std::string& path, int width, int height, int channels, const uint8_t* data);
// Any format OpenImageIO chooses from the file name; data is float (is_float) or 8-bit.
void write_with_oiio(const std::string& path, int width, int height, int channels, bool is_float, const void* data);

// Where the plugin is looked for: beside the running executable, then the build folder.
std::vector<std::string> oiio_plugin_candidates();
// True once the plugin has been loaded in this process (tests: a PNG/EXR read must not load it).
bool oiio_plugin_loaded();

} // namespace iblcheck::imagefile
