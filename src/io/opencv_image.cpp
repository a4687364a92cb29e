#include "panmap/io/opencv_image.h"

namespace panmap {

cv::Mat asMat(ColorImage& image) {
  return cv::Mat(image.height(), image.width(), CV_8UC3, image.data());
}
cv::Mat asMat(const ColorImage& image) {
  return cv::Mat(image.height(), image.width(), CV_8UC3, const_cast<Rgb8*>(image.data()));
}
cv::Mat asMat(DepthImage& image) {
  return cv::Mat(image.height(), image.width(), CV_16UC1, image.data());
}
cv::Mat asMat(const DepthImage& image) {
  return cv::Mat(image.height(), image.width(), CV_16UC1, const_cast<uint16_t*>(image.data()));
}
cv::Mat asMat(LabelImage& image) {
  return cv::Mat(image.height(), image.width(), CV_32SC1, image.data());
}
cv::Mat asMat(const LabelImage& image) {
  return cv::Mat(image.height(), image.width(), CV_32SC1, const_cast<int32_t*>(image.data()));
}

cv::Mat asMat(Image<float>& image) {
  return cv::Mat(image.height(), image.width(), CV_32FC1, image.data());
}
cv::Mat asMat(const Image<float>& image) {
  return cv::Mat(image.height(), image.width(), CV_32FC1, const_cast<float*>(image.data()));
}

ColorImage colorFromMat(const cv::Mat& rgb) {
  CV_Assert(rgb.type() == CV_8UC3);
  ColorImage image(rgb.cols, rgb.rows);
  rgb.copyTo(asMat(image));
  return image;
}

DepthImage depthFromMat(const cv::Mat& depth) {
  CV_Assert(depth.type() == CV_16UC1);
  DepthImage image(depth.cols, depth.rows);
  depth.copyTo(asMat(image));
  return image;
}

LabelImage labelsFromMat(const cv::Mat& labels) {
  CV_Assert(labels.type() == CV_32SC1);
  LabelImage image(labels.cols, labels.rows);
  labels.copyTo(asMat(image));
  return image;
}

}  // namespace panmap
