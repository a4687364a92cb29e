#pragma once

#include <opencv2/core.hpp>

#include "panmap/core/image.h"

namespace panmap {

/// A cv::Mat header over an image's pixels (no copy; the image must outlive it).
/// Colour maps to CV_8UC3 in R G B order (not OpenCV's usual B G R).
cv::Mat asMat(ColorImage& image);
/// @copydoc asMat(ColorImage&)
cv::Mat asMat(const ColorImage& image);
/// A CV_16UC1 header over a depth image's pixels (no copy).
cv::Mat asMat(DepthImage& image);
/// @copydoc asMat(DepthImage&)
cv::Mat asMat(const DepthImage& image);
/// A CV_32SC1 header over a label image's pixels (no copy).
cv::Mat asMat(LabelImage& image);
/// @copydoc asMat(LabelImage&)
cv::Mat asMat(const LabelImage& image);

/// A CV_32FC1 header over a float image's pixels (no copy).
cv::Mat asMat(Image<float>& image);
/// @copydoc asMat(Image<float>&)
cv::Mat asMat(const Image<float>& image);

/// Copies a CV_8UC3 matrix in R G B order into a colour image.
ColorImage colorFromMat(const cv::Mat& rgb);
/// Copies a CV_16UC1 matrix into a depth image.
DepthImage depthFromMat(const cv::Mat& depth);
/// Copies a CV_32SC1 matrix into a label image.
LabelImage labelsFromMat(const cv::Mat& labels);

}  // namespace panmap
