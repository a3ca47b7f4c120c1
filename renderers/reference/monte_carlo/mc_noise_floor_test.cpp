// The relative RMSE the noise floor is measured with (monte_carlo.h, relative_rmse), on values worked by
// hand: sqrt(mean over covered pixels and channels of (a − b)² / (m² + 0.01)), m = (a + b)/2.
#include <gtest/gtest.h>

#include <cmath>

#include "renderers/reference/monte_carlo/monte_carlo.h"

using namespace iblcheck;

// Its own namespace: the test programs of one group compile as unity batches (tests/CMakeLists.txt).
namespace mc_noise_floor_test {

TEST(McNoiseFloor, RelativeRmseOverCoveredPixels) {
    cv::Mat a(1, 3, CV_32FC3, cv::Scalar(1, 1, 1)), b(1, 3, CV_32FC3, cv::Scalar(1, 1, 1));
    b.at<cv::Vec3f>(0, 0) = cv::Vec3f(1.1f, 1.1f, 1.1f);
    b.at<cv::Vec3f>(0, 2) = cv::Vec3f(100, 100, 100); // not covered: ignored
    cv::Mat cov(1, 3, CV_32FC1, cv::Scalar(1));
    cov.at<float>(0, 2) = 0;
    double mean = 0;
    const double d = double(1.1f) - 1, m = 0.5 * (1 + double(1.1f));
    const double expected = std::sqrt(d * d / (m * m + 0.01) / 2); // pixel 0's term, pixel 1's is 0
    EXPECT_NEAR(relative_rmse(a, b, cov, &mean), expected, 1e-12);
    EXPECT_NEAR(mean, (m + 1) / 2, 1e-12);
    EXPECT_EQ(relative_rmse(a, a, cov), 0.0);
    EXPECT_EQ(relative_rmse(a, b, cv::Mat(1, 3, CV_32FC1, cv::Scalar(0))), 0.0) << "nothing covered";
    // Black pixels: the 0.01 keeps the term finite (d = 0.1, m = 0.05 -> 0.01 / 0.0125).
    cv::Mat z(1, 1, CV_32FC3, cv::Scalar(0, 0, 0)), w(1, 1, CV_32FC3, cv::Scalar(0.1, 0.1, 0.1));
    const double dz = double(0.1f), mz = 0.5 * dz;
    EXPECT_NEAR(relative_rmse(z, w, cv::Mat(1, 1, CV_32FC1, cv::Scalar(1))), dz / std::sqrt(mz * mz + 0.01), 1e-12);
}
} // namespace mc_noise_floor_test
