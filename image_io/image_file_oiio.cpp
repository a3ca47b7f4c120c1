// Loads libiblcheck_oiio.so (image_io/oiio_plugin/) on first use and calls it (image_formats.h).
#include <dlfcn.h>

#include <filesystem>
#include <mutex>

#include <fmt/format.h>

#include "image_io/image_formats.h"
#include "image_io/oiio_plugin/oiio_plugin_abi.h"
#include "kernel/errors.h"

namespace iblcheck::imagefile {

namespace {

constexpr const char* kPluginName = "libiblcheck_oiio.so";

struct Plugin {
    IblcheckOiioReadFn read = nullptr;
    IblcheckOiioWriteFn write = nullptr;
    std::string problem; // why it could not be loaded
};

std::once_flag g_once;
Plugin g_plugin;
bool g_loaded = false;

void load_plugin() {
    std::string tried;
    for (const std::string& path : oiio_plugin_candidates()) {
        std::error_code ec;
        if (!std::filesystem::exists(path, ec)) {
            tried += (tried.empty() ? "" : ", ") + path;
            continue;
        }
        // RTLD_LOCAL: OpenImageIO's own dependencies stay out of the global symbol namespace.
        void* h = dlopen(path.c_str(), RTLD_NOW | RTLD_LOCAL);
        if (!h) {
            g_plugin.problem = fmt::format("cannot load {}: {}", path, dlerror());
            return;
        }
        g_plugin.read = reinterpret_cast<IblcheckOiioReadFn>(dlsym(h, IBLCHECK_OIIO_READ_SYMBOL));
        g_plugin.write = reinterpret_cast<IblcheckOiioWriteFn>(dlsym(h, IBLCHECK_OIIO_WRITE_SYMBOL));
        if (!g_plugin.read || !g_plugin.write) {
            g_plugin.problem = fmt::format("{} lacks {}", path, IBLCHECK_OIIO_READ_SYMBOL);
            return;
        }
        g_loaded = true;
        return;
    }
    g_plugin.problem = fmt::format("{} not found (looked for {}); rebuild iblcheck", kPluginName, tried);
}

const Plugin& plugin(const std::string& path) {
    std::call_once(g_once, load_plugin);
    if (!g_loaded)
        throw EnvironmentError(fmt::format("{}: this format is read through OpenImageIO, but {}", path, g_plugin.problem));
    return g_plugin;
}

// The harness's side of a read: where the pixels go, and why the header's claim was refused.
struct ReadTarget {
    const std::string& path;
    const IblcheckOiioImage& image; // its width and height are set when alloc is called
    std::vector<float>& data;
    std::string refused;
};

// No ratio bound for the formats OpenImageIO reads (TIFF's zstd, old Radiance RLE...): the
// claim is held to kMaxImagePixels before the buffer is allocated. nullptr tells the plugin no.
float* alloc_into(void* ctx, size_t count) {
    auto* t = static_cast<ReadTarget*>(ctx);
    try {
        check_claimed_size(t->path, uint64_t(t->image.width), uint64_t(t->image.height), 0, 0);
    } catch (const InputError& e) {
        t->refused = e.what();
        return nullptr;
    }
    t->data.resize(count);
    return t->data.data();
}

} // namespace

std::vector<std::string> oiio_plugin_candidates() {
    std::vector<std::string> out;
    std::error_code ec;
    const std::filesystem::path self = std::filesystem::read_symlink("/proc/self/exe", ec);
    if (!ec) out.push_back((self.parent_path() / kPluginName).string());
#ifdef IBLCHECK_PLUGIN_DIR
    const std::string built = (std::filesystem::path(IBLCHECK_PLUGIN_DIR) / kPluginName).string();
    if (out.empty() || out.front() != built) out.push_back(built);
#endif
    return out;
}

bool oiio_plugin_loaded() { return g_loaded; }

RawImage read_with_oiio(const std::string& path, bool unassociated_alpha) {
    const Plugin& p = plugin(path);
    RawImage img;
    IblcheckOiioImage out{};
    ReadTarget target{path, out, img.data, {}};
    out.alloc = alloc_into;
    out.ctx = &target;
    const int rc = p.read(path.c_str(), unassociated_alpha ? 1 : 0, &out);
    if (!target.refused.empty()) throw InputError(target.refused);
    const std::string why = out.error;
    if (rc == kOiioCannotOpen)
        throw InputError(fmt::format("{}: cannot read image ({})", path, why.empty() ? "unknown format or corrupt file" : why));
    if (rc != kOiioOk)
        throw InputError(fmt::format("{}: corrupt or truncated image data ({})", path, why.empty() ? "read failed" : why));
    img.width = out.width;
    img.height = out.height;
    img.channels = out.channels;
    img.hdr = out.hdr != 0;
    img.reader = "openimageio";
    return img;
}

void write_with_oiio(const std::string& path, int width, int height, int channels, bool is_float, const void* data) {
    const Plugin& p = plugin(path);
    char error[1024] = "";
    const int rc = p.write(path.c_str(), width, height, channels, is_float ? 1 : 0, data, error, sizeof error);
    if (rc == kOiioCannotCreate) throw InputError(fmt::format("{}: cannot create image writer ({})", path, error));
    if (rc == kOiioCannotOpen) throw InputError(fmt::format("{}: cannot open for writing ({})", path, error));
    if (rc != kOiioOk) throw InputError(fmt::format("{}: write failed ({})", path, error));
}

} // namespace iblcheck::imagefile
