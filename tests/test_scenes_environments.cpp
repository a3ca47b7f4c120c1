// Scenes (renderers/scenes) and environments (renderers/environments): the shared inputs of every method.
#include <OpenImageIO/imageio.h>
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <limits>

#include "kernel/errors.h"
#include "kernel/options.h"
#include "renderers/environments/environment.h"
#include "renderers/environments/procedural.h"
#include "renderers/scenes/coverage.h"
#include "renderers/scenes/scene.h"
#include "tests/test_support.h"

using namespace iblcheck;
namespace fs = std::filesystem;

// Its own namespace: the test programs of one group compile as one unity unit (tests/CMakeLists.txt).
namespace test_scenes_environments {

namespace {
constexpr double kPi = 3.14159265358979323846;

fs::path temp_file(const std::string& name) {
    static const fs::path dir = testutil::temp_dir("test_env");
    return dir / name;
}

void write_exr(const fs::path& path, const cv::Mat& img) {
    auto out = OIIO::ImageOutput::create(path.string());
    ASSERT_TRUE(out);
    OIIO::ImageSpec spec(img.cols, img.rows, 3, OIIO::TypeDesc::FLOAT);
    ASSERT_TRUE(out->open(path.string(), spec));
    ASSERT_TRUE(out->write_image(OIIO::TypeDesc::FLOAT, img.ptr<float>(0)));
    out->close();
}

double len(Vec3f v) { return std::sqrt(double(v.x) * v.x + double(v.y) * v.y + double(v.z) * v.z); }
} // namespace

// ---------------------------------------------------------------- environments

TEST(Environment, DirectionUvRoundTrip) {
    for (int j = 1; j < 40; ++j)
        for (int i = 0; i < 80; ++i) {
            float u = (i + 0.5f) / 80, v = j / 40.0f;
            float d[3];
            uv_to_direction(u, v, d);
            EXPECT_NEAR(std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]), 1.0, 1e-6);
            float u2, v2;
            direction_to_uv(d, u2, v2);
            EXPECT_NEAR(u2, u, 2e-6) << i << "," << j;
            EXPECT_NEAR(v2, v, 2e-6) << i << "," << j;
        }
}

TEST(Environment, MinusZIsThePanoramaCentre) {
    float d[3] = {0, 0, -1}, u, v;
    direction_to_uv(d, u, v);
    EXPECT_NEAR(u, 0.5, 1e-7);
    EXPECT_NEAR(v, 0.5, 1e-7);
    float up[3] = {0, 1, 0};
    direction_to_uv(up, u, v);
    EXPECT_NEAR(v, 0.0, 1e-7);
    // +X is a quarter turn right of the centre: u = 0.75.
    float px[3] = {1, 0, 0};
    direction_to_uv(px, u, v);
    EXPECT_NEAR(u, 0.75, 1e-7);
    EXPECT_NEAR(v, 0.5, 1e-7);
}

TEST(Environment, ConstantSamplesTheConstant) {
    Environment e = load_environment("constant:0.25,0.5,2");
    EXPECT_EQ(e.equirect.cols, 2 * e.equirect.rows);
    for (float dy : {-1.0f, -0.3f, 0.0f, 0.7f, 1.0f}) {
        float d[3] = {std::sqrt(1 - dy * dy), dy, 0}, c[3];
        sample_bilinear(e, d, c);
        EXPECT_FLOAT_EQ(c[0], 0.25f);
        EXPECT_FLOAT_EQ(c[1], 0.5f);
        EXPECT_FLOAT_EQ(c[2], 2.0f);
    }
    Environment one = load_environment("constant:1");
    float d[3] = {0, 0, -1}, c[3];
    sample_bilinear(one, d, c);
    EXPECT_FLOAT_EQ(c[0], 1.0f);
    EXPECT_EQ(one.content_hash.size(), 16u);
    EXPECT_NE(one.content_hash, e.content_hash);
}

TEST(Environment, BilinearAtPixelCentresAndWrap) {
    cv::Mat img(8, 16, CV_32FC3, cv::Scalar(0, 0, 0));
    img.at<cv::Vec3f>(4, 0) = {1, 1, 1};
    img.at<cv::Vec3f>(4, 15) = {3, 3, 3};
    fs::path p = temp_file("wrap.exr");
    write_exr(p, img);
    Environment e = load_environment(p.string());
    float d[3], c[3];
    uv_to_direction(0.5f / 16, 4.5f / 8, d); // centre of pixel (0,4)
    sample_bilinear(e, d, c);
    EXPECT_NEAR(c[0], 1.0, 1e-5);
    uv_to_direction(0.0f, 4.5f / 8, d); // the seam: halfway between pixel 15 and pixel 0
    sample_bilinear(e, d, c);
    EXPECT_NEAR(c[0], 2.0, 1e-5);
    // Rotation: +90 deg about +Y brings the seam content (direction +Z) to +X... lookup at R(-90)·d.
    e.rotation_deg = 90;
    float px[3] = {1, 0, 0};
    // R_y(-90)·(+X) = +Z, which is the seam (u = 1 or 0), v = 0.5 -> between rows 3 and 4: half of 2.
    sample_bilinear(e, px, c);
    EXPECT_NEAR(c[0], 1.0, 1e-5);
}

TEST(Environment, NaNIsAnInputErrorWithCountAndLocation) {
    cv::Mat img(16, 32, CV_32FC3, cv::Scalar(1, 1, 1));
    img.at<cv::Vec3f>(3, 7)[1] = std::numeric_limits<float>::quiet_NaN();
    img.at<cv::Vec3f>(5, 9)[0] = std::numeric_limits<float>::infinity();
    fs::path p = temp_file("nan.exr");
    write_exr(p, img);
    try {
        load_environment(p.string());
        FAIL() << "expected InputError";
    } catch (const InputError& e) {
        std::string m = e.what();
        EXPECT_NE(m.find("2 non-finite"), std::string::npos) << m;
        EXPECT_NE(m.find("(7, 3)"), std::string::npos) << m;
    }
}

// Issue 30: constant:1e39 became inf as a float and constant:1e38 overflowed the renderers' sums;
// both gave an all-black render that passed and could be blessed.
TEST(Environment, RadianceBeyondWhatTheRenderersSumIsRefused) {
    auto message_of = [](const std::string& spec) -> std::string {
        try {
            load_environment(spec);
        } catch (const Error& e) {
            return e.what();
        }
        return "(loaded)";
    };
    std::string m = message_of("constant:1e39");
    EXPECT_NE(m.find("'1e39' is beyond a 32-bit float's range"), std::string::npos) << m;
    m = message_of("constant:1,1e38,1");
    EXPECT_NE(m.find("environment 'constant:1,1e38,1': radiance 1e+38 at pixel (0, 0) channel 1 is above 1e+30"),
              std::string::npos)
        << m;
    EXPECT_EQ(message_of("constant:1e30"), "(loaded)");
    EXPECT_EQ(message_of("sky_sun"), "(loaded)");
    cv::Mat img(16, 32, CV_32FC3, cv::Scalar(1, 1, 1));
    img.at<cv::Vec3f>(4, 9)[2] = 2e31f;
    fs::path p = temp_file("hot.exr");
    write_exr(p, img);
    m = message_of(p.string());
    EXPECT_NE(m.find("(" + p.string() + "): radiance 2e+31 at pixel (9, 4) channel 2"), std::string::npos) << m;
}

TEST(Options, NumbersBeyondAFloatAreRefused) {
    OptionMap o;
    o.set("env_rotation", "1e39");
    o.set("roughness", "-4e38");
    o.set("ao", "3e38");
    EXPECT_THROW(o.get_double("env_rotation"), UsageError); // was inf once cast to float
    EXPECT_THROW(o.get_double("roughness"), UsageError);
    EXPECT_EQ(o.get_double("ao"), 3e38);
}

TEST(Environment, NegativesAreClampedAndCounted) {
    cv::Mat img(16, 32, CV_32FC3, cv::Scalar(0.5, 0.5, 0.5));
    img.at<cv::Vec3f>(2, 2) = {-0.004f, 0.5f, -1.0f};
    img.at<cv::Vec3f>(8, 30)[1] = -0.25f;
    fs::path p = temp_file("neg.exr");
    write_exr(p, img);
    Environment e = load_environment(p.string());
    EXPECT_EQ(e.negatives_clamped, 3);
    EXPECT_EQ(e.equirect.at<cv::Vec3f>(2, 2)[0], 0.0f);
    EXPECT_EQ(e.equirect.at<cv::Vec3f>(2, 2)[2], 0.0f);
    EXPECT_EQ(e.equirect.at<cv::Vec3f>(8, 30)[1], 0.0f);
    double mn;
    cv::minMaxLoc(e.equirect.reshape(1), &mn);
    EXPECT_GE(mn, 0.0);
}

TEST(Environment, NonEquirectAspectIsAnInputError) {
    cv::Mat img(16, 16, CV_32FC3, cv::Scalar(1, 1, 1));
    fs::path p = temp_file("square.exr");
    write_exr(p, img);
    EXPECT_THROW(load_environment(p.string()), InputError);
    EXPECT_THROW(load_environment(temp_file("missing.exr").string()), InputError);
}

TEST(Environment, UnknownSpecIsAUsageError) {
    EXPECT_THROW(load_environment("moonlight"), UsageError);
    EXPECT_THROW(load_environment("blender:mars"), UsageError);
    EXPECT_THROW(load_environment("constant:x"), UsageError);
    try {
        load_environment("moonlight");
    } catch (const UsageError& e) {
        EXPECT_NE(std::string(e.what()).find("sky_sun"), std::string::npos);
    }
}

TEST(Environment, ProceduralStudioAndSkySun) {
    Environment st = load_environment("studio");
    EXPECT_EQ(st.equirect.cols, 1024);
    EXPECT_EQ(st.equirect.rows, 512);
    double mn, mx;
    cv::minMaxLoc(st.equirect.reshape(1), &mn, &mx);
    EXPECT_GE(mn, 0.025);
    EXPECT_GE(mx, 40.0);
    EXPECT_LE(mx, 50.001);
    EXPECT_EQ(load_environment("studio").content_hash, st.content_hash); // deterministic

    Environment sky = load_environment("sky_sun");
    EXPECT_EQ(sky.equirect.cols, 1024);
    // The sun: its centre direction reads the sun's radiance; the zenith reads the sky.
    double el = procedural::kSunElevationDeg * kPi / 180, az = procedural::kSunAzimuthDeg * kPi / 180;
    float sun[3] = {float(std::cos(el) * std::sin(az)), float(std::sin(el)), float(-std::cos(el) * std::cos(az))};
    float c[3];
    sample_bilinear(sky, sun, c);
    EXPECT_NEAR(c[0], procedural::kSunRadiance[0], 1.0);
    EXPECT_GT(sun[2], 0.5f); // in front of the camera (+Z side)
    float up[3] = {0, 1, 0}, down[3] = {0, -1, 0}, zs[3], gr[3];
    sample_bilinear(sky, up, zs);
    sample_bilinear(sky, down, gr);
    EXPECT_NEAR(zs[2], procedural::kSkyZenith[2], 0.01);
    EXPECT_LT(gr[0] + gr[1] + gr[2], 0.5 * (zs[0] + zs[1] + zs[2]));
    EXPECT_GT(c[1] / zs[1], 5e4);
}

TEST(Environment, BlenderSunriseLoadsWithClampedNegatives) {
    Environment e;
    try {
        e = load_environment("blender:sunrise");
    } catch (const InputError& err) {
        GTEST_SKIP() << "blender:sunrise not present (" << err.what() << ")";
    }
    EXPECT_EQ(e.equirect.cols, 2 * e.equirect.rows);
    EXPECT_GT(e.negatives_clamped, 0);
    double mn;
    cv::minMaxLoc(e.equirect.reshape(1), &mn);
    EXPECT_GE(mn, 0.0);
    EXPECT_FALSE(e.source_path.empty());
}

// ---------------------------------------------------------------- scenes

TEST(Scene, IntersectHitsAndMisses) {
    Scene s = build_scene("sphere", {});
    ASSERT_EQ(s.spheres.size(), 1u);
    Hit h = intersect(s, {0, 0, 5}, {0, 0, -1});
    ASSERT_TRUE(h.hit);
    EXPECT_NEAR(h.t, 4.0, 1e-5);
    EXPECT_NEAR(h.normal.z, 1.0, 1e-6);
    EXPECT_FALSE(intersect(s, {1.01f, 0, 5}, {0, 0, -1}).hit);
    EXPECT_FALSE(intersect(s, {0, 0, 5}, {0, 0, 1}).hit); // pointing away
    Hit g = intersect(s, {0.6f, 0.0f, 5}, {0, 0, -1});
    ASSERT_TRUE(g.hit);
    EXPECT_NEAR(g.normal.x, 0.6, 1e-6);
    EXPECT_NEAR(g.normal.z, 0.8, 1e-6);
}

TEST(Scene, NormalsAreUnitOverTheImage) {
    for (const auto& info : scene_catalog()) {
        Scene s = build_scene(info.name, {});
        int hits = 0;
        for (int y = 0; y < s.height; y += 3)
            for (int x = 0; x < s.width; x += 3) {
                Vec3f o, d;
                camera_ray(s, s.width, s.height, x + 0.5, y + 0.5, o, d);
                EXPECT_NEAR(len(d), 1.0, 1e-6);
                Hit h = intersect(s, o, d);
                if (!h.hit) continue;
                ++hits;
                EXPECT_NEAR(len(h.normal), 1.0, 1e-6);
                EXPECT_GT(-(h.normal.x * d.x + h.normal.y * d.y + h.normal.z * d.z), 0.0) << info.name;
            }
        EXPECT_GT(hits, 0) << info.name;
    }
}

// A render's coverage (coverage.h) is the sphere the camera ray through each pixel's centre hits first.
TEST(Scene, CoverageIsTheSphereAtEachPixelCentre) {
    for (const char* name : {"sphere", "roughness_sweep", "sphere_field"}) {
        const Scene s = build_scene(name, {});
        const int w = s.width / 2, h = s.height; // not the scene's aspect: the camera takes the size given
        const SphereCoverage c = sphere_coverage(s, w, h);
        ASSERT_EQ(c.ids.type(), CV_32S);
        ASSERT_EQ(c.ids.cols, w);
        ASSERT_EQ(c.ids.rows, h);
        ASSERT_EQ(c.spheres.size(), s.spheres.size());
        for (size_t i = 0; i < s.spheres.size(); ++i) {
            EXPECT_EQ(c.spheres[i].label, i < s.labels.size() ? s.labels[i] : "sphere " + std::to_string(i));
            EXPECT_EQ(c.spheres[i].roughness, s.spheres[i].material.roughness);
            EXPECT_EQ(c.spheres[i].metallic, s.spheres[i].material.metallic);
        }
        int background = 0;
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x) {
                Vec3f o, d;
                camera_ray(s, w, h, x + 0.5, y + 0.5, o, d);
                const Hit hit = intersect(s, o, d);
                ASSERT_EQ(c.ids.at<int>(y, x), hit.hit ? hit.sphere : -1) << name << " at " << x << "," << y;
                background += !hit.hit;
            }
        EXPECT_GT(background, 0) << name;
    }
}

namespace {
// The pixels whose coverage is not the sphere the camera ray through the centre hits (-1: background).
int wrong_coverage_pixels(const Scene& s, const SphereCoverage& c) {
    int wrong = 0;
    for (int y = 0; y < c.ids.rows; ++y)
        for (int x = 0; x < c.ids.cols; ++x) {
            Vec3f o, d;
            camera_ray(s, c.ids.cols, c.ids.rows, x + 0.5, y + 0.5, o, d);
            const Hit hit = intersect(s, o, d);
            wrong += c.ids.at<int>(y, x) != (hit.hit ? hit.sphere : -1);
        }
    return wrong;
}
} // namespace

// The coverage is traced once per geometry and size in a process (issue 33), and what it depends on
// is in that key: a moved or resized sphere, another camera or size gets its own map, and a map handed
// out is the caller's (changing it changes no later one).
TEST(Scene, CoverageOfAChangedGeometryIsTracedAgain) {
    const Scene base = build_scene("roughness_sweep", {});
    SphereCoverage first = sphere_coverage(base, 132, 24);
    ASSERT_EQ(wrong_coverage_pixels(base, first), 0);
    first.ids.setTo(7);
    EXPECT_EQ(wrong_coverage_pixels(base, sphere_coverage(base, 132, 24)), 0);
    Scene moved = base, resized = base, zoomed = base, turned = base, perspective = base;
    moved.spheres[1].center.x += 0.3f;
    resized.spheres[2].radius *= 0.5f;
    zoomed.camera.half_height *= 0.8f;
    turned.camera.eye = {0.5f, 0.2f, 5.0f};
    perspective.camera.orthographic = false;
    for (const Scene* s : {&moved, &resized, &zoomed, &turned, &perspective}) {
        const SphereCoverage c = sphere_coverage(*s, 132, 24);
        EXPECT_EQ(wrong_coverage_pixels(*s, c), 0);
        EXPECT_GT(cv::countNonZero(c.ids != sphere_coverage(base, 132, 24).ids), 0); // the change shows
    }
    EXPECT_EQ(wrong_coverage_pixels(base, sphere_coverage(base, 66, 12)), 0);
}

TEST(Scene, CameraConvention) {
    Scene s = build_scene("sphere", {});
    Vec3f o, d;
    camera_ray(s, 128, 128, 0, 0, o, d); // top-left corner: ndc (-1, 1)
    EXPECT_NEAR(o.x, -1.1, 1e-6);
    EXPECT_NEAR(o.y, 1.1, 1e-6);
    EXPECT_NEAR(o.z, 5.0, 1e-6);
    EXPECT_NEAR(d.z, -1.0, 1e-7);
    camera_ray(s, 128, 128, 64, 64, o, d);
    EXPECT_NEAR(o.x, 0.0, 1e-6);
    EXPECT_NEAR(o.y, 0.0, 1e-6);
}

TEST(Scene, UnknownSceneIsAUsageErrorListingTheValidOnes) {
    try {
        build_scene("teapot", {});
        FAIL();
    } catch (const UsageError& e) {
        std::string m = e.what();
        EXPECT_NE(m.find("teapot"), std::string::npos);
        EXPECT_NE(m.find("roughness_sweep"), std::string::npos);
        EXPECT_NE(m.find("furnace"), std::string::npos);
    }
}

TEST(Scene, MaterialOptions) {
    OptionMap o;
    o.set("roughness", "0.3");
    o.set("metallic", "1");
    o.set("base_color", "0.9,0.5,0.1");
    Scene s = build_scene("sphere", o);
    EXPECT_FLOAT_EQ(s.spheres[0].material.roughness, 0.3f);
    EXPECT_FLOAT_EQ(s.spheres[0].material.metallic, 1.0f);
    EXPECT_FLOAT_EQ(s.spheres[0].material.base_color.z, 0.1f);
    Scene d = build_scene("sphere", {});
    EXPECT_FLOAT_EQ(d.spheres[0].material.roughness, 0.5f);
    EXPECT_FLOAT_EQ(d.spheres[0].material.metallic, 0.0f);
    OptionMap bad;
    bad.set("roughness", "1.5");
    EXPECT_THROW(build_scene("sphere", bad), UsageError);
    EXPECT_EQ(scene_option_keys(), (std::vector<std::string>{"roughness", "metallic", "base_color", "frame", "bump_amplitude",
                                                             "bump_frequency", "roughness_bias", "camera_shift", "ao"}));
    // ao reaches every sphere of any scene, and is checked like the other material options.
    OptionMap occluded;
    occluded.set("ao", "0.25");
    for (const Sphere& sp : build_scene("roughness_sweep", occluded).spheres) EXPECT_FLOAT_EQ(sp.material.ao, 0.25f);
    EXPECT_FLOAT_EQ(build_scene("sphere", {}).spheres[0].material.ao, 1.0f);
    occluded.set("ao", "1.5");
    EXPECT_THROW(build_scene("sphere", occluded), UsageError);
}

TEST(Scene, BumpySphereMovesItsDetailEachFrame) {
    OptionMap f0, f3;
    f3.set("frame", "3");
    Scene a = build_scene("bumpy_sphere", f0), b = build_scene("bumpy_sphere", f3);
    ASSERT_EQ(a.spheres.size(), 1u);
    EXPECT_GT(a.spheres[0].bump_amplitude, 0.0f);
    EXPECT_FLOAT_EQ(a.spheres[0].material.roughness, 0.05f);
    EXPECT_FLOAT_EQ(b.spheres[0].bump_phase - a.spheres[0].bump_phase, 3 * 0.9f);
}

TEST(Scene, RoughnessSweepLayout) {
    Scene s = build_scene("roughness_sweep", {});
    ASSERT_EQ(s.spheres.size(), 22u);
    ASSERT_EQ(s.labels.size(), 22u);
    EXPECT_EQ(s.width, 528);
    EXPECT_EQ(s.height, 96);
    for (int i = 0; i < 22; ++i) {
        EXPECT_NEAR(s.spheres[i].material.roughness, (i % 11) * 0.1, 1e-6);
        EXPECT_FLOAT_EQ(s.spheres[i].material.metallic, i < 11 ? 1.0f : 0.0f);
    }
    EXPECT_EQ(s.labels[3], "metal r=0.3");
    EXPECT_EQ(s.labels[11 + 10], "dielectric r=1");
    // The centre pixel of each 48 px cell hits its sphere.
    for (int i = 0; i < 22; ++i) {
        Vec3f o, d;
        camera_ray(s, s.width, s.height, (i % 11) * 48 + 24, (i / 11) * 48 + 24, o, d);
        Hit h = intersect(s, o, d);
        ASSERT_TRUE(h.hit);
        EXPECT_EQ(h.sphere, i);
    }
}

TEST(Scene, FurnaceLayout) {
    Scene s = build_scene("furnace", {});
    ASSERT_EQ(s.spheres.size(), 5u);
    for (int i = 0; i < 5; ++i) {
        EXPECT_FLOAT_EQ(s.spheres[i].material.roughness, 0.25f * i);
        EXPECT_FLOAT_EQ(s.spheres[i].material.metallic, 1.0f);
        EXPECT_FLOAT_EQ(s.spheres[i].material.base_color.x, 1.0f);
    }
    EXPECT_FLOAT_EQ(build_scene("furnace_dielectric", {}).spheres[2].material.metallic, 0.0f);
}

// The environment hash is FNV-1a-64 (environment.h): the published test vectors (draft-eastlake-fnv,
// "a" and "foobar"; the empty input is the offset basis itself). Fails with the old basis
// 1469598103934665603, which had lost a digit.
TEST(Environment, ContentHashIsFnv1a64) {
    auto bytes = [](const std::string& s) {
        cv::Mat m(1, int(s.size()), CV_8UC1);
        for (size_t i = 0; i < s.size(); ++i) m.at<unsigned char>(0, int(i)) = (unsigned char)s[i];
        return m;
    };
    EXPECT_EQ(fnv1a64_hex(cv::Mat()), "cbf29ce484222325");
    EXPECT_EQ(fnv1a64_hex(bytes("a")), "af63dc4c8601ec8c");
    EXPECT_EQ(fnv1a64_hex(bytes("foobar")), "85944171f73967e8");
    // Rows are hashed in order without padding: a 2x3 view equals its 6 bytes in a row.
    const cv::Mat two = bytes("foobar").reshape(1, 2);
    EXPECT_EQ(fnv1a64_hex(two), "85944171f73967e8");
}

} // namespace test_scenes_environments
