#include "ibl_precompute.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>

#include "astc_storage.h"
#include "env_layout.h"
#include "kernel/errors.h"
#include "kernel/profile.h"
#include "mip_chain.h"
#include "precompute_store.h"
#include "renderers/mobile/descriptor_types.h"
#include "renderers/mobile/push_constants.h"
#include "renderers/option_table.h"

namespace iblcheck {

namespace {

uint32_t groups(uint32_t n, uint32_t local = 8) { return (n + local - 1) / local; }

bool is_astc(const std::string& storage) { return storage == "astc_hdr" || storage == "astc_ldr_rgbm"; }
bool is_rgbm(const std::string& storage) { return storage == "rgbm8" || storage == "astc_ldr_rgbm"; }

// The RGBM range (option rgbm_range), read from the base level of the source cube, which the
// chain's sharpest level holds: by default its peak, as UE4.26 derives a mobile capture's
// MaxValueRGBM from the captured data (ReflectionCaptureComponent: unless bModifyMaxValueRGBM), so
// the format's verdict is its precision over the range it needs, not an arbitrary clip; a fixed
// range (Karis 2009: 6 in UE3's captures) is kept as asked. Either way r.rgbm_clipped_energy is the
// share of that level's radiant energy above the range (texels weighted by their solid angle,
// ∝ (1 + u² + v²)^(−3/2)): what the clamp loses where the reflection is sharpest.
void fit_rgbm_range(vk::Context& ctx, const vk::Image& source, float requested, IblResources& r) {
    const uint32_t n = source.width;
    const std::vector<float> texels = ctx.download(source, 0);
    float peak = 0;
    for (size_t i = 0; i < texels.size(); i += 4) peak = std::max({peak, texels[i], texels[i + 1], texels[i + 2]});
    r.rgbm_range = requested > 0 ? requested : std::max(peak, 1e-3f);
    double total = 0, clipped = 0;
    for (uint32_t face = 0; face < 6; ++face)
        for (uint32_t y = 0; y < n; ++y)
            for (uint32_t x = 0; x < n; ++x) {
                const double u = (x + 0.5) / n * 2 - 1, v = (y + 0.5) / n * 2 - 1, w = std::pow(1 + u * u + v * v, -1.5);
                const float* c = &texels[4 * ((size_t(face) * n + y) * n + x)];
                for (int k = 0; k < 3; ++k) {
                    total += w * c[k];
                    clipped += w * std::max(0.0, double(c[k]) - r.rgbm_range);
                }
            }
    r.rgbm_clipped_energy = total > 0 ? clipped / total : 0.0;
}

VkFormat storage_format(const std::string& storage, bool native_r11g11b10) {
    if (storage == "rgba32f") return VK_FORMAT_R32G32B32A32_SFLOAT;
    if (storage == "rgba16f") return VK_FORMAT_R16G16B16A16_SFLOAT;
    if (storage == "rgbm8") return VK_FORMAT_R8G8B8A8_UNORM;
    if (storage == "r11g11b10") return native_r11g11b10 ? VK_FORMAT_B10G11R11_UFLOAT_PACK32 : VK_FORMAT_R16G16B16A16_SFLOAT;
    // ASTC: the prefilter pass writes full precision for the host's encoder (astc_storage.h).
    if (is_astc(storage)) return VK_FORMAT_R32G32B32A32_SFLOAT;
    throw UsageError("option 'storage': unknown value '" + storage +
                     "'; valid: rgba16f, rgba32f, rgbm8, r11g11b10, astc_hdr, astc_ldr_rgbm");
}

// Every level of every layer of `encoded` (RGBA32F, as the prefilter pass wrote it) through the
// ASTC codec; returns the decoded texels in an RGBA16F image of the same shape, which the shading
// pass samples. The encode and decode times are precompute passes (on the CPU).
vk::Image astc_round_trip(vk::Context& ctx, const vk::Image& encoded, const PrecomputeSettings& s, float rgbm_range,
                          std::vector<PassTiming>& timings) {
    ProfileStage stage("astc_encode");
    AstcFormat format;
    format.profile = s.storage == "astc_hdr" ? AstcProfile::hdr : AstcProfile::ldr_rgbm;
    format.block = astc_block_from_option(s.astc_block);
    format.rgbm_range = rgbm_range;
    AstcCodec codec(format);
    vk::Image decoded =
        ctx.create_image(VK_FORMAT_R16G16B16A16_SFLOAT, encoded.width, encoded.height, encoded.mips, encoded.cube);
    std::vector<vk::Buffer> staging;
    double encode_ms = 0, decode_ms = 0;
    for (uint32_t m = 0; m < encoded.mips; ++m) {
        const uint32_t w = std::max(1u, encoded.width >> m), h = std::max(1u, encoded.height >> m);
        const size_t layer_texels = size_t(w) * h;
        std::vector<float> texels = ctx.download(encoded, m);
        staging.push_back(ctx.create_buffer(layer_texels * encoded.layers * 8, VK_BUFFER_USAGE_TRANSFER_SRC_BIT));
        auto* dst = staging.back().as<uint16_t>();
        for (uint32_t layer = 0; layer < encoded.layers; ++layer) {
            AstcRoundTrip rt = codec.round_trip(texels.data() + layer * layer_texels * 4, w, h);
            std::memcpy(dst + layer * layer_texels * 4, rt.decoded_half.data(), layer_texels * 8);
            encode_ms += rt.encode_ms;
            decode_ms += rt.decode_ms;
        }
    }
    ctx.submit([&](VkCommandBuffer cmd) {
        ctx.transition(cmd, decoded, VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL);
        for (uint32_t m = 0; m < encoded.mips; ++m) ctx.copy_buffer_to_image(cmd, staging[m], decoded, m);
        ctx.transition(cmd, decoded, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, VK_IMAGE_LAYOUT_GENERAL);
    });
    timings.push_back({"astc_encode", encode_ms, false, true});
    timings.push_back({"astc_decode", decode_ms, false, true});
    return decoded;
}

} // namespace

uint64_t storage_level_bytes(const std::string& storage, const std::string& astc_block, uint32_t width, uint32_t height,
                             uint32_t layers) {
    if (is_astc(storage)) return astc_image_bytes(width, height, astc_block_from_option(astc_block)) * layers;
    uint64_t texels = uint64_t(width) * height * layers;
    if (storage == "rgba32f") return texels * 16;
    if (storage == "rgba16f") return texels * 8;
    if (storage == "rgbm8" || storage == "r11g11b10") return texels * 4;
    throw UsageError("option 'storage': unknown value '" + storage + "'");
}

vk::Defines storage_defines(const PrecomputeSettings& s, const IblResources& r) {
    vk::Defines d = glsl_defines({{"storage", s.storage}, {"mip_mapping", s.mip_mapping}, {"env_layout", s.env_layout}});
    if (is_rgbm(s.storage)) d["RGBM_RANGE"] = std::to_string(r.rgbm_range);
    if (s.storage == "r11g11b10" && r.native_r11g11b10) d["STORAGE_NATIVE_R11G11B10"] = "1";
    return d;
}

namespace {

// The checks that need the layout: a bad option is a usage error before any GPU work.
void check_layout_settings(const PrecomputeSettings& s, EnvLayout layout, uint32_t mips) {
    if (s.prefiltered) check_layout_mips(layout, s.cube_size, mips);
    if (is_astc(s.storage)) astc_block_from_option(s.astc_block); // a bad block is a usage error before any work
}

// The equirect in a host-visible staging buffer (RGB float → RGBA32F, alpha 1) and the image it is
// copied into; the copy is recorded with the passes.
struct EquirectUpload {
    vk::Buffer staging;
    vk::Image image;
};

EquirectUpload stage_equirect(vk::Context& ctx, const cv::Mat& eq) {
    const uint32_t ew = uint32_t(eq.cols), eh = uint32_t(eq.rows);
    EquirectUpload up;
    up.staging = ctx.create_buffer(VkDeviceSize(ew) * eh * 16, VK_BUFFER_USAGE_TRANSFER_SRC_BIT);
    float* dst = up.staging.as<float>();
    for (uint32_t y = 0; y < eh; ++y) {
        const float* row = eq.ptr<float>(int(y));
        for (uint32_t x = 0; x < ew; ++x) {
            std::memcpy(dst + 4 * (size_t(y) * ew + x), row + 3 * x, 12);
            dst[4 * (size_t(y) * ew + x) + 3] = 1.0f;
        }
    }
    up.image = ctx.create_image(VK_FORMAT_R32G32B32A32_SFLOAT, ew, eh, 1, false);
    return up;
}

// The images and buffers the derived passes write (the source cube and SH9 are the radiance chain's,
// copied in). A pass that is off gets a 1×1 placeholder so the shading pass's descriptor set is the
// same shape for every variant.
void allocate_outputs(vk::Context& ctx, const PrecomputeSettings& s, EnvLayout layout, const LayoutExtent& extent, uint32_t mips,
                      IblResources& r) {
    r.source_cube = ctx.create_image(VK_FORMAT_R32G32B32A32_SFLOAT, s.cube_size, s.cube_size, r.full_mips, true);
    r.native_r11g11b10 = s.storage == "r11g11b10" && ctx.format_supports(VK_FORMAT_B10G11R11_UFLOAT_PACK32,
                                                                         VK_FORMAT_FEATURE_STORAGE_IMAGE_BIT |
                                                                             VK_FORMAT_FEATURE_SAMPLED_IMAGE_FILTER_LINEAR_BIT);
    VkFormat pf = storage_format(s.storage, r.native_r11g11b10);
    if (!ctx.format_supports(pf, VK_FORMAT_FEATURE_STORAGE_IMAGE_BIT | VK_FORMAT_FEATURE_SAMPLED_IMAGE_FILTER_LINEAR_BIT))
        throw EnvironmentError(ctx.info().device_name + ": storage=" + s.storage +
                               " needs a format usable as a filtered storage image");
    r.prefiltered = s.prefiltered ? ctx.create_image(pf, extent.width, extent.height, mips, layout == EnvLayout::cube)
                                  : ctx.create_image(VK_FORMAT_R16G16B16A16_SFLOAT, 1, 1, 1, true);
    if (s.prefiltered) {
        r.texel_count = layout_texel_count(layout, s.cube_size, mips);
        for (uint32_t m = 0; m < mips; ++m)
            r.texture_bytes += storage_level_bytes(s.storage, s.astc_block, std::max(1u, extent.width >> m),
                                                   std::max(1u, extent.height >> m), extent.layers);
    }
    r.sh = ctx.create_buffer(10 * 16);
    r.lut = s.lut ? ctx.create_image(VK_FORMAT_R16G16_SFLOAT, s.lut_size, s.lut_size, 1, false)
                  : ctx.create_image(VK_FORMAT_R16G16_SFLOAT, 1, 1, 1, false);
    r.irradiance = s.irradiance_cube
                       ? ctx.create_image(VK_FORMAT_R32G32B32A32_SFLOAT, s.irradiance_size, s.irradiance_size, 1, true)
                       : ctx.create_image(VK_FORMAT_R32G32B32A32_SFLOAT, 1, 1, 1, true);
}

// What every pass records into: one command buffer, timed per pass. Each pass warms its pipeline
// up outside the timed span (the first dispatch of a pipeline pays lavapipe's JIT).
struct Recording {
    GpuSession& gpu;
    vk::Context& ctx;
    VkCommandBuffer cmd;
    vk::GpuTimer& timer;
    const PrecomputeSettings& s;
    IblResources& r;
};

void record_upload(const Recording& rec, const EquirectUpload& up) {
    vk::Context& ctx = rec.ctx;
    ctx.transition(rec.cmd, up.image, VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL);
    ctx.copy_buffer_to_image(rec.cmd, up.staging, up.image);
    ctx.transition(rec.cmd, up.image, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, VK_IMAGE_LAYOUT_GENERAL);
}

// The images the passes write, from UNDEFINED to GENERAL (the layout every pass uses).
void record_outputs_general(const Recording& rec) {
    IblResources& r = rec.r;
    for (vk::Image* img : {&r.source_cube, &r.prefiltered, &r.lut, &r.irradiance})
        rec.ctx.transition(rec.cmd, *img, VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_GENERAL);
}

// Every level and layer of `src` into `dst` (same format and shape; both in GENERAL).
void record_copy_image(const Recording& rec, const vk::Image& src, const vk::Image& dst) {
    std::vector<VkImageCopy> regions(src.mips);
    for (uint32_t m = 0; m < src.mips; ++m) {
        VkImageCopy& c = regions[m];
        c.srcSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, m, 0, src.layers};
        c.dstSubresource = c.srcSubresource;
        c.extent = {std::max(1u, src.width >> m), std::max(1u, src.height >> m), 1};
    }
    vkCmdCopyImage(rec.cmd, src.image, VK_IMAGE_LAYOUT_GENERAL, dst.image, VK_IMAGE_LAYOUT_GENERAL, uint32_t(regions.size()),
                   regions.data());
    rec.ctx.barrier(rec.cmd);
}

// The rgba32f chain in the storage format, level by level (encode_storage.comp).
void record_encode_storage(const Recording& rec, const vk::ComputePipeline& p, const vk::Image& chain, const LayoutExtent& extent,
                           uint32_t mips) {
    for (uint32_t m = 0; m < mips; ++m) {
        const EncodeStoragePush pe{std::max(1u, extent.width >> m), std::max(1u, extent.height >> m)};
        const std::vector<vk::Binding> b = {vk::Binding::storage_image(0, chain.storage_views[m]),
                                            vk::Binding::storage_image(1, rec.r.prefiltered.storage_views[m])};
        if (m == 0) {
            p.warm_up(rec.cmd, b, &pe, sizeof pe);
            rec.timer.begin(rec.cmd, "encode_storage");
        }
        p.dispatch(rec.cmd, b, &pe, sizeof pe, groups(pe.width), groups(pe.height), extent.layers);
    }
    rec.timer.end(rec.cmd);
    rec.ctx.barrier(rec.cmd);
}

// Equirect → cube mip 0, supersampled so each cube texel averages the equirect pixels it covers.
void record_equirect_to_cube(const Recording& rec, const vk::ComputePipeline& p, const vk::Image& equirect) {
    const PrecomputeSettings& s = rec.s;
    EquirectToCubePush pe{s.cube_size, std::max(1u, (equirect.width + 4 * s.cube_size - 1) / (4 * s.cube_size)),
                          s.env_rotation_deg};
    std::vector<vk::Binding> be = {vk::Binding::sampled_image(0, equirect.sampled_view, rec.ctx.equirect_sampler()),
                                   vk::Binding::storage_image(1, rec.r.source_cube.storage_views[0])};
    p.warm_up(rec.cmd, be, &pe, sizeof pe);
    rec.timer.begin(rec.cmd, "equirect_to_cube");
    p.dispatch(rec.cmd, be, &pe, sizeof pe, groups(s.cube_size), groups(s.cube_size), 6);
    rec.timer.end(rec.cmd);
    rec.ctx.barrier(rec.cmd);
}

// The source cube's full mip chain, each level a box filter of the one above.
void record_downsample(const Recording& rec, const vk::ComputePipeline& p) {
    const PrecomputeSettings& s = rec.s;
    const IblResources& r = rec.r;
    if (r.full_mips > 1) {
        const DownsamplePush size1{std::max(1u, s.cube_size >> 1)};
        p.warm_up(rec.cmd,
                  {vk::Binding::storage_image(0, r.source_cube.storage_views[0]),
                   vk::Binding::storage_image(1, r.source_cube.storage_views[1])},
                  &size1, sizeof size1);
    }
    rec.timer.begin(rec.cmd, "downsample_cube");
    for (uint32_t m = 1; m < r.full_mips; ++m) {
        const DownsamplePush size{std::max(1u, s.cube_size >> m)};
        p.dispatch(rec.cmd,
                   {vk::Binding::storage_image(0, r.source_cube.storage_views[m - 1]),
                    vk::Binding::storage_image(1, r.source_cube.storage_views[m])},
                   &size, sizeof size, groups(size.dst_size), groups(size.dst_size), 6);
        rec.ctx.barrier(rec.cmd);
    }
    rec.timer.end(rec.cmd);
}

// GGX-prefiltered specular levels, one roughness per mip, in the storage format and layout asked for.
void record_prefilter(const Recording& rec, const vk::ComputePipeline& p, const LayoutExtent& extent, uint32_t mips) {
    const PrecomputeSettings& s = rec.s;
    const IblResources& r = rec.r;
    vk::Context& ctx = rec.ctx;
    for (uint32_t m = 0; m < mips; ++m) {
        if (m == 0) { // warm-up: a mip-0 copy of one workgroup, overwritten below
            PrefilterPush pw{0,
                             s.cube_size,
                             s.cube_size,
                             s.prefilter_samples,
                             float(cubemap_max_mip(s.cube_size)),
                             float(mips - 1),
                             float(r.full_mips - 1)};
            p.warm_up(rec.cmd,
                      {vk::Binding::sampled_image(0, r.source_cube.sampled_view, ctx.linear_sampler()),
                       vk::Binding::storage_image(1, r.prefiltered.storage_views[0])},
                      &pw, sizeof pw);
            rec.timer.begin(rec.cmd, "prefilter_ggx");
        }
        // dst_size: the cube's face size, or a 2D layout level's width (its height follows).
        const uint32_t w = std::max(1u, extent.width >> m), h = std::max(1u, extent.height >> m);
        PrefilterPush pp{
            m, w, s.cube_size, s.prefilter_samples, float(cubemap_max_mip(s.cube_size)), float(mips - 1), float(r.full_mips - 1)};
        p.dispatch(rec.cmd,
                   {vk::Binding::sampled_image(0, r.source_cube.sampled_view, ctx.linear_sampler()),
                    vk::Binding::storage_image(1, r.prefiltered.storage_views[m])},
                   &pp, sizeof pp, groups(w), groups(h), extent.layers);
    }
    rec.timer.end(rec.cmd);
    ctx.barrier(rec.cmd);
}

// SH9 from a 32² level (or the base if smaller): enough for 9 coefficients, and exact weights.
void record_sh9(const Recording& rec, const vk::ComputePipeline& p) {
    const PrecomputeSettings& s = rec.s;
    uint32_t sh_mip = s.cube_size > 32 ? uint32_t(std::log2(double(s.cube_size / 32))) : 0;
    const Sh9Push sh_size{s.cube_size >> sh_mip};
    std::vector<vk::Binding> bsh = {vk::Binding::storage_image(0, rec.r.source_cube.storage_views[sh_mip]),
                                    vk::Binding::storage_buffer(1, rec.r.sh)};
    p.warm_up(rec.cmd, bsh, &sh_size, sizeof sh_size);
    rec.timer.begin(rec.cmd, "sh9_project");
    p.dispatch(rec.cmd, bsh, &sh_size, sizeof sh_size, 1);
    rec.timer.end(rec.cmd);
}

// The split-sum's DFG table (env_brdf=lut); its pipeline is only built when the variant uses it.
void record_dfg_lut(const Recording& rec) {
    const PrecomputeSettings& s = rec.s;
    const auto& p_lut = rec.gpu.pipeline("dfg_lut.comp", {}, {kStorageImage}, sizeof(DfgLutPush));
    const DfgLutPush pl{s.lut_size, s.lut_samples};
    p_lut.warm_up(rec.cmd, {vk::Binding::storage_image(0, rec.r.lut.storage_views[0])}, &pl, sizeof pl);
    rec.timer.begin(rec.cmd, "dfg_lut");
    p_lut.dispatch(rec.cmd, {vk::Binding::storage_image(0, rec.r.lut.storage_views[0])}, &pl, sizeof pl, groups(s.lut_size),
                   groups(s.lut_size), 1);
    rec.timer.end(rec.cmd);
}

// The diffuse irradiance cube (diffuse=irradiance_cube), convolved from a 16² level.
void record_irradiance(const Recording& rec) {
    const PrecomputeSettings& s = rec.s;
    const auto& p_irr = rec.gpu.pipeline("irradiance_cube.comp", {}, {kStorageImage, kStorageImage}, sizeof(IrradiancePush));
    uint32_t src_mip = s.cube_size > 16 ? uint32_t(std::log2(double(s.cube_size / 16))) : 0;
    const IrradiancePush pi{s.irradiance_size, s.cube_size >> src_mip};
    std::vector<vk::Binding> bi = {vk::Binding::storage_image(0, rec.r.source_cube.storage_views[src_mip]),
                                   vk::Binding::storage_image(1, rec.r.irradiance.storage_views[0])};
    p_irr.warm_up(rec.cmd, bi, &pi, sizeof pi);
    rec.timer.begin(rec.cmd, "irradiance_cube");
    p_irr.dispatch(rec.cmd, bi, &pi, sizeof pi, groups(s.irradiance_size), groups(s.irradiance_size), 6);
    rec.timer.end(rec.cmd);
}

} // namespace

// The radiance chain: the source cube's box pyramid, its SH9 and the GGX-prefiltered chain in
// rgba32f (prefilter_ggx.comp with storage=rgba32f), computed once per environment and chain geometry
// (size, levels, samples, mip_mapping, env_layout, rotation) and shared by every variant that only
// stores it differently, or adds the DFG table or the irradiance cube. The ci suite's 35 precomputes
// come from 15 chains; each used to pay its own prefilter (~1.6 s under GALLIUM_OVERRIDE_CPU_CAPS=sse4.1,
// the portability runs' largest stage). With the stores empty the ci suite's precompute took 39.2 s of
// worker time, and 13.1 s with the chains shared (issue 33).
PrecomputeSettings chain_settings(const PrecomputeSettings& s) {
    const PrecomputeSettings defaults;
    PrecomputeSettings c = s;
    c.storage = "rgba32f";
    c.astc_block = defaults.astc_block;
    c.rgbm_range = defaults.rgbm_range;
    c.lut = false;
    c.lut_size = defaults.lut_size;
    c.lut_samples = defaults.lut_samples;
    c.irradiance_cube = false;
    c.irradiance_size = defaults.irradiance_size;
    return c;
}

namespace {

// One submission of passes into `r`, each timed; their GPU timings are appended as precompute passes.
template <class Record>
void submit_timed(GpuSession& gpu, const PrecomputeSettings& s, IblResources& r, std::vector<PassTiming>& timings,
                  Record&& record) {
    vk::Context& ctx = gpu.ctx();
    vk::GpuTimer timer(ctx, 8);
    ctx.submit([&](VkCommandBuffer cmd) {
        const Recording rec{gpu, ctx, cmd, timer, s, r};
        timer.reset(cmd);
        record(rec);
        ctx.barrier(cmd);
    });
    for (auto& [name, ms] : timer.results()) timings.push_back({name, ms, true, true});
}

IblResources compute_radiance_chain(GpuSession& gpu, const Environment& env, const PrecomputeSettings& c, EnvLayout layout,
                                    uint32_t mips, std::vector<PassTiming>& timings) {
    vk::Context& ctx = gpu.ctx();
    IblResources r;
    r.full_mips = cubemap_max_mip(c.cube_size) + 1;
    r.levels = mips;
    const LayoutExtent extent = layout_extent(layout, c.cube_size);
    const EquirectUpload equirect = stage_equirect(ctx, env.equirect);
    allocate_outputs(ctx, c, layout, extent, mips, r);
    const auto& p_e2c = gpu.pipeline("equirect_to_cube.comp", {}, {kSampled, kStorageImage}, sizeof(EquirectToCubePush));
    const auto& p_down = gpu.pipeline("downsample_cube.comp", {}, {kStorageImage, kStorageImage}, sizeof(DownsamplePush));
    const auto& p_sh = gpu.pipeline("sh9_project.comp", {}, {kStorageImage, kStorageBuffer}, sizeof(Sh9Push));
    const auto& p_pre =
        gpu.pipeline("prefilter_ggx.comp", storage_defines(c, r), {kSampled, kStorageImage}, sizeof(PrefilterPush));
    submit_timed(gpu, c, r, timings, [&](const Recording& rec) {
        record_upload(rec, equirect);
        record_outputs_general(rec);
        record_equirect_to_cube(rec, p_e2c, equirect.image);
        record_downsample(rec, p_down);
        if (c.prefiltered) record_prefilter(rec, p_pre, extent, mips);
        record_sh9(rec, p_sh);
    });
    return r;
}

struct ChainEntry {
    IblResources chain;
    std::vector<PassTiming> timings;
};

// The radiance chain through the session's cache (the runner's workers each keep to a chain:
// harness/batch_queue.h).
std::shared_ptr<ChainEntry> radiance_chain(GpuSession& gpu, const Environment& env, const PrecomputeSettings& s, EnvLayout layout,
                                           uint32_t mips) {
    const PrecomputeSettings c = chain_settings(s);
    const std::string key = "chain;" + precompute_key(env.content_hash, c);
    if (auto e = gpu.cached<ChainEntry>(key)) return e;
    auto e = std::make_shared<ChainEntry>();
    e->chain = compute_radiance_chain(gpu, env, c, layout, mips, e->timings);
    gpu.store(key, e);
    return e;
}

} // namespace

IblResources run_precompute(GpuSession& gpu, const Environment& env, const PrecomputeSettings& s,
                            std::vector<PassTiming>& timings) {
    vk::Context& ctx = gpu.ctx();
    if (s.cube_size < 8 || s.cube_size > 2048 || (s.cube_size & (s.cube_size - 1)))
        throw UsageError("option 'cube_size': " + std::to_string(s.cube_size) + " must be a power of two in 8..2048");
    IblResources r;
    r.full_mips = cubemap_max_mip(s.cube_size) + 1;
    const EnvLayout layout = env_layout_from_option(s.env_layout);
    // The chain reaches r = 1 whatever the base size, or the configuration is refused (issue 27).
    check_layout_settings(s, layout, s.mips);
    const uint32_t mips = s.prefiltered ? chain_levels(s.mip_mapping, layout, s.cube_size, s.mips) : 1;
    r.levels = mips;
    const LayoutExtent extent = layout_extent(layout, s.cube_size);

    // The shared passes' timings are this precompute's too: they are what it costs.
    const std::shared_ptr<ChainEntry> chain = radiance_chain(gpu, env, s, layout, mips);
    timings.insert(timings.end(), chain->timings.begin(), chain->timings.end());
    allocate_outputs(ctx, s, layout, extent, mips, r);
    std::memcpy(r.sh.mapped, chain->chain.sh.mapped, size_t(r.sh.size));
    // RGBM's range comes from the source cube, before the chain is encoded.
    if (s.prefiltered && is_rgbm(s.storage)) fit_rgbm_range(ctx, chain->chain.source_cube, s.rgbm_range, r);
    const auto& p_enc =
        gpu.pipeline("encode_storage.comp", storage_defines(s, r), {kStorageImage, kStorageImage}, sizeof(EncodeStoragePush));
    submit_timed(gpu, s, r, timings, [&](const Recording& rec) {
        record_outputs_general(rec);
        record_copy_image(rec, chain->chain.source_cube, r.source_cube);
        if (s.prefiltered) record_encode_storage(rec, p_enc, chain->chain.prefiltered, extent, mips);
        if (s.lut) record_dfg_lut(rec);
        if (s.irradiance_cube) record_irradiance(rec);
    });
    // ASTC is encoded on the host, so its round trip follows the GPU passes.
    if (s.prefiltered && is_astc(s.storage)) r.prefiltered = astc_round_trip(ctx, r.prefiltered, s, r.rgbm_range, timings);
    return r;
}

std::string precompute_key(const std::string& env_id, const PrecomputeSettings& s) {
    return "ibl;" + env_id + ";" + std::to_string(s.cube_size) + ";" + std::to_string(s.mips) + ";" +
           std::to_string(s.prefilter_samples) + ";" + s.mip_mapping + ";" + s.storage + ";" + std::to_string(s.rgbm_range) +
           ";" + s.astc_block + ";" + s.env_layout + ";" + std::to_string(s.prefiltered) + ";" + std::to_string(s.lut) + ";" +
           std::to_string(s.lut_size) + ";" + std::to_string(s.lut_samples) + ";" + std::to_string(s.irradiance_cube) + ";" +
           std::to_string(s.irradiance_size) + ";" + std::to_string(s.env_rotation_deg);
}

std::shared_ptr<IblResources> precompute_cached(GpuSession& gpu, const Environment& env, const PrecomputeSettings& s,
                                                std::vector<PassTiming>& timings, bool& cached) {
    const std::string key = precompute_key(env.content_hash, s);
    // No shader hash in the key: the session's pipelines are cached by name and defines too, so a
    // session renders with the sources it first compiled either way.
    struct Entry {
        std::shared_ptr<IblResources> ibl;
        std::vector<PassTiming> timings;
    };
    if (auto e = gpu.cached<Entry>(key)) {
        cached = true;
        timings.insert(timings.end(), e->timings.begin(), e->timings.end());
        return e->ibl;
    }
    cached = false;
    auto e = std::make_shared<Entry>();
    // A precompute an earlier run stored on disk (precompute_store.h: keyed by every input), else
    // computed now and stored.
    const std::string disk_key = precompute_store_key(gpu, env, s);
    if (std::optional<IblResources> stored = load_precompute(gpu.ctx(), disk_key, e->timings)) {
        cached = true;
        e->ibl = std::make_shared<IblResources>(std::move(*stored));
    } else {
        ProfileStage stage("precompute");
        e->ibl = std::make_shared<IblResources>(run_precompute(gpu, env, s, e->timings));
        save_precompute(gpu.ctx(), disk_key, *e->ibl, e->timings);
    }
    timings.insert(timings.end(), e->timings.begin(), e->timings.end());
    gpu.store(key, e);
    return e->ibl;
}

} // namespace iblcheck
