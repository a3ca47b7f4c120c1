// The C interface between the harness and libiblcheck_oiio.so (image_io/oiio_plugin/), the one place
// that links OpenImageIO. Plain C types only, so nothing but these two functions crosses the
// dlopen boundary.
#pragma once
#include <stddef.h>

extern "C" {

struct IblcheckOiioImage {
    int width, height, channels, hdr;         // filled by the plugin
    float* (*alloc)(void* ctx, size_t count); // the caller's buffer for width*height*channels floats, or
                                              // nullptr: the caller refuses that size (width and height set)
    void* ctx;
    char error[1024]; // why, when the call fails
};

// Return codes of both calls.
enum { kOiioOk = 0, kOiioCannotOpen = 1, kOiioReadFailed = 2, kOiioCannotCreate = 3, kOiioWriteFailed = 4 };

// Reads subimage 0 as float (HDR formats) or 8/16-bit codes scaled to [0,1] (all others).
typedef int (*IblcheckOiioReadFn)(const char* path, int unassociated_alpha, IblcheckOiioImage* out);
// Writes float (is_float) or 8-bit data; the format follows the file name.
typedef int (*IblcheckOiioWriteFn)(const char* path, int width, int height, int channels, int is_float, const void* data,
                                   char* error, size_t error_size);

#define IBLCHECK_OIIO_READ_SYMBOL "iblcheck_oiio_read_v1"
#define IBLCHECK_OIIO_WRITE_SYMBOL "iblcheck_oiio_write_v1"
}
