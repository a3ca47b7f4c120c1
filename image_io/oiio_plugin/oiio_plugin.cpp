// libiblcheck_oiio.so: OpenImageIO for the image formats the harness does not decode itself (every
// format but OpenEXR and PNG). Loaded with dlopen on first use (image_io/image_file_oiio.cpp), so
// the ~250 libraries Debian's OpenImageIO links are loaded only by a process that reads such a file.
#include <OpenImageIO/imageio.h>

#include <cstdio>
#include <exception>
#include <string>
#include <vector>

#include "image_io/oiio_plugin/oiio_plugin_abi.h"

namespace {

void set_error(char* dst, size_t size, const std::string& why) { std::snprintf(dst, size, "%s", why.c_str()); }

bool is_hdr_format(const OIIO::ImageSpec& spec, const std::string& format_name) {
    if (format_name == "openexr" || format_name == "hdr") return true;
    return spec.format.basetype == OIIO::TypeDesc::HALF || spec.format.basetype == OIIO::TypeDesc::FLOAT ||
           spec.format.basetype == OIIO::TypeDesc::DOUBLE;
}

int read_image(const char* path, int unassociated_alpha, IblcheckOiioImage* out) {
    // PNG's alpha is unassociated by definition: without this OpenImageIO multiplies colour by it.
    OIIO::ImageSpec config;
    if (unassociated_alpha) config.attribute("oiio:UnassociatedAlpha", 1);
    auto in = OIIO::ImageInput::open(path, &config);
    if (!in) {
        set_error(out->error, sizeof out->error, OIIO::geterror());
        return kOiioCannotOpen;
    }
    const OIIO::ImageSpec spec = in->spec();
    out->width = spec.width;
    out->height = spec.height;
    out->channels = spec.nchannels;
    out->hdr = is_hdr_format(spec, in->format_name());
    if (spec.width <= 0 || spec.height <= 0 || spec.nchannels <= 0) return kOiioOk; // the caller refuses it
    const size_t n = size_t(spec.width) * spec.height * spec.nchannels;
    float* data = out->alloc(out->ctx, n);
    if (!data) return kOiioReadFailed; // the caller refused the header's size (and says why)
    bool ok;
    if (out->hdr) {
        ok = in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::FLOAT, data);
    } else if (spec.format.basetype == OIIO::TypeDesc::UINT8) {
        // Divide by 255 here so values are exactly k/255.0f (what the FLIP tool reads).
        std::vector<unsigned char> raw(n);
        ok = in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::UINT8, raw.data());
        for (size_t i = 0; i < n; ++i) data[i] = float(raw[i]) / 255.0f;
    } else {
        std::vector<unsigned short> raw(n);
        ok = in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::UINT16, raw.data());
        for (size_t i = 0; i < n; ++i) data[i] = float(raw[i]) / 65535.0f;
    }
    if (!ok) {
        set_error(out->error, sizeof out->error, in->geterror());
        return kOiioReadFailed;
    }
    in->close();
    return kOiioOk;
}

int write_image(const char* path, int width, int height, int channels, int is_float, const void* data, char* error,
                size_t error_size) {
    auto out = OIIO::ImageOutput::create(path);
    if (!out) {
        set_error(error, error_size, OIIO::geterror());
        return kOiioCannotCreate;
    }
    const OIIO::TypeDesc type = is_float ? OIIO::TypeDesc::FLOAT : OIIO::TypeDesc::UINT8;
    OIIO::ImageSpec spec(width, height, channels, type);
    if (!out->open(path, spec)) {
        set_error(error, error_size, out->geterror());
        return kOiioCannotOpen;
    }
    if (!out->write_image(type, data)) {
        set_error(error, error_size, out->geterror());
        return kOiioWriteFailed;
    }
    out->close();
    return kOiioOk;
}

} // namespace

extern "C" __attribute__((visibility("default"))) int iblcheck_oiio_read_v1(const char* path, int unassociated_alpha,
                                                                            IblcheckOiioImage* out) {
    try {
        return read_image(path, unassociated_alpha, out);
    } catch (const std::exception& e) {
        set_error(out->error, sizeof out->error, e.what());
        return kOiioReadFailed;
    }
}

extern "C" __attribute__((visibility("default"))) int iblcheck_oiio_write_v1(const char* path, int width, int height,
                                                                             int channels, int is_float, const void* data,
                                                                             char* error, size_t error_size) {
    try {
        return write_image(path, width, height, channels, is_float, data, error, error_size);
    } catch (const std::exception& e) {
        set_error(error, error_size, e.what());
        return kOiioWriteFailed;
    }
}
