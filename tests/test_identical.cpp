// Bit-identical images (metrics/identical.h): identical_finite, which lets every metric skip its
// work, and bit_identical, which decides whether bless rewrites a golden, whether a report shares a
// test's EXR with its baseline and whether a repeated render is deterministic. CPU only.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include <opencv2/core.hpp>

#include "metrics/identical.h"

using namespace iblcheck;

// Its own namespace: the test programs of one group compile as one unity unit (tests/CMakeLists.txt).
namespace test_identical {

namespace {

cv::Mat ramp(int w, int h) {
    cv::Mat m(h, w, CV_32FC3);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) m.at<cv::Vec3f>(y, x) = cv::Vec3f(float(x), float(y), float(x * y) / 7.0f);
    return m;
}

} // namespace

TEST(BitIdentical, SameBytesAreIdenticalAndOneBitIsNot) {
    const cv::Mat a = ramp(16, 8);
    cv::Mat b = a.clone();
    EXPECT_TRUE(bit_identical(a, b));
    EXPECT_TRUE(identical_finite(a, b));
    b.at<cv::Vec3f>(5, 9)[1] = std::nextafter(b.at<cv::Vec3f>(5, 9)[1], 1e9f);
    EXPECT_FALSE(bit_identical(a, b));
    EXPECT_FALSE(identical_finite(a, b));
}

TEST(BitIdentical, NanBytesAreIdenticalButNotFinite) {
    cv::Mat a = ramp(4, 4);
    a.at<cv::Vec3f>(2, 2)[0] = std::numeric_limits<float>::quiet_NaN();
    const cv::Mat b = a.clone();
    EXPECT_TRUE(bit_identical(a, b));     // a golden with the same NaN is not rewritten
    EXPECT_FALSE(identical_finite(a, b)); // but its metrics are not known without computing them
    EXPECT_TRUE(bit_identical(a, a));
    EXPECT_FALSE(identical_finite(a, a)); // the same pixels still hold a NaN
}

TEST(BitIdentical, SizeAndTypeMustMatch) {
    const cv::Mat a = ramp(8, 8);
    EXPECT_FALSE(bit_identical(a, ramp(8, 4))); // a shorter image whose bytes start the same
    EXPECT_FALSE(bit_identical(ramp(8, 4), a));
    EXPECT_FALSE(bit_identical(a, a.reshape(1))); // the same bytes as one channel
    cv::Mat u8(8, 8, CV_8UC3, cv::Scalar::all(0)), u8b = u8.clone();
    EXPECT_TRUE(bit_identical(u8, u8b));
    EXPECT_FALSE(identical_finite(u8, u8b)); // float images only
}

TEST(BitIdentical, ComparesTheRowsOfAViewNotWhatLiesBetweenThem) {
    cv::Mat big_a = ramp(32, 16), big_b = ramp(32, 16);
    big_b.at<cv::Vec3f>(2, 20)[2] = -1.0f; // outside the views below, between their first two rows in memory
    const cv::Mat va = big_a(cv::Rect(4, 2, 8, 6)), vb = big_b(cv::Rect(4, 2, 8, 6));
    ASSERT_FALSE(va.isContinuous());
    EXPECT_TRUE(bit_identical(va, vb));
    EXPECT_TRUE(identical_finite(va, vb));
    big_b.at<cv::Vec3f>(7, 11)[0] += 1.0f; // inside them
    EXPECT_FALSE(bit_identical(va, vb));
}

} // namespace test_identical
