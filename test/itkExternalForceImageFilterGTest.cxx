/*=========================================================================
 *
 *  Copyright NumFOCUS
 *
 *  Licensed under the Apache License, Version 2.0 (the "License");
 *  you may not use this file except in compliance with the License.
 *  You may obtain a copy of the License at
 *
 *         http://www.apache.org/licenses/LICENSE-2.0.txt
 *
 *  Unless required by applicable law or agreed to in writing, software
 *  distributed under the License is distributed on an "AS IS" BASIS,
 *  WITHOUT WARRANTIES OR CONDITIONS OF ANY KIND, either express or implied.
 *  See the License for the specific language governing permissions and
 *  limitations under the License.
 *
 *=========================================================================*/

#include "itkEllipsoidPhantom.h"
#include "itkExternalForceImageFilter.h"
#include "itkImageRegionIteratorWithIndex.h"
#include "itkSampledGaussianSmoothing.h"
#include "edmTestUtilities.h"
#include "gtest/gtest.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <utility>
#include <vector>

namespace
{
constexpr unsigned int Dimension = 3;
using ImageType = itk::Image<unsigned char, Dimension>;
using ForceImageType = itk::Image<itk::CovariantVector<float, Dimension>, Dimension>;
using DirectionType = ImageType::DirectionType;
using edm::test::Rotation;
using edm::test::UpdateAndGetError;
using PointType = ImageType::PointType;

} // namespace

TEST(ExternalForceImageFilter, SmoothsWithAGaussianOfSigmaInPhysicalUnits)
{
  // A step along x between voxels 31 and 32, 0.5 mm voxels along x, Sigma 2 mm:
  // |grad (G * I)| is a Gaussian of standard deviation 2 mm centred on the
  // step and the force, its derivative, goes as -x exp(-x^2 / 8) along x (x
  // in mm from the step): largest at |x| = 2 mm, pointing to the step, and
  // nothing along y and z.
  using StepImageType = itk::Image<float, 3>;
  auto                    image = StepImageType::New();
  StepImageType::SizeType size;
  size[0] = 64;
  size[1] = 5;
  size[2] = 4;
  image->SetRegions(size);
  StepImageType::SpacingType spacing;
  spacing[0] = 0.5;
  spacing[1] = 1.0;
  spacing[2] = 2.0;
  image->SetSpacing(spacing);
  image->Allocate();
  for (itk::ImageRegionIteratorWithIndex<StepImageType> it(image, image->GetBufferedRegion()); !it.IsAtEnd(); ++it)
  {
    it.Set(it.GetIndex()[0] >= 32 ? 100.0f : 0.0f);
  }
  using FilterType = itk::ExternalForceImageFilter<StepImageType, ForceImageType>;
  auto filter = FilterType::New();
  filter->SetInput(image);
  filter->SetSigma(2.0);
  filter->Update();

  auto force = [&](itk::IndexValueType i) {
    ForceImageType::IndexType index = { { i, 2, 1 } };
    const auto                f = filter->GetOutput()->GetPixel(index);
    EXPECT_EQ(f[1], 0.0f);
    EXPECT_EQ(f[2], 0.0f);
    return static_cast<double>(f[0]);
  };
  auto                position = [](itk::IndexValueType i) { return 0.5 * (static_cast<double>(i) - 31.5); }; // mm
  auto                expected = [](double x) { return -x * std::exp(-x * x / 8.0); };
  itk::IndexValueType strongest = 0;
  for (itk::IndexValueType i = 0; i < 64; ++i)
  {
    if (std::abs(force(i)) > std::abs(force(strongest)))
    {
      strongest = i;
    }
    EXPECT_LE(force(i) * position(i), 0.0) << "the force points to the step, at x = " << position(i);
  }
  EXPECT_NEAR(std::abs(position(strongest)), 2.0, 0.5);
  // The profile's shape within 2 sigma, relative to its value at 1.75 mm
  // (central differences on 0.5 mm voxels widen it by a few per cent).
  for (const itk::IndexValueType i : { 33, 37, 39, 27, 25 })
  {
    const double ratio = expected(position(i)) / expected(position(35));
    EXPECT_NEAR(force(i) / force(35), ratio, 0.08 * std::abs(ratio)) << "x = " << position(i) << " mm";
  }
}

TEST(SampledGaussianSmoothing, ImpulseResponseIsTheNormalisedGaussianInPhysicalUnits)
{
  // The smoothing of the force field and of the region force
  // (itkSampledGaussianSmoothing.h): an impulse in the middle of a 2-D image
  // of 0.5 x 2 mm pixels, sigma 1.5 mm, gives exp(-x^2 / (2 s^2)) exp(-y^2 /
  // (2 s^2)) sampled at the pixel centres, normalised to a unit sum along
  // each axis; a constant image stays constant (the border pixels repeat).
  using FloatImageType = itk::Image<float, 2>;
  const auto make = [](float value) {
    auto                     image = FloatImageType::New();
    FloatImageType::SizeType size = { { 41, 21 } };
    image->SetRegions(size);
    FloatImageType::SpacingType spacing;
    spacing[0] = 0.5;
    spacing[1] = 2.0;
    image->SetSpacing(spacing);
    image->Allocate();
    image->FillBuffer(value);
    return image;
  };
  FloatImageType::Pointer impulse = make(0.0f);
  impulse->SetPixel({ { 20, 10 } }, 1.0f);
  FloatImageType::Pointer scratch = make(0.0f);
  auto                    threader = itk::MultiThreaderBase::New();
  itk::SmoothWithSampledGaussian<FloatImageType>(impulse, scratch, 1.5, threader);
  const auto axisWeights = [](double spacing, int radius) {
    std::vector<double> w;
    double              sum = 0.0;
    for (int k = -radius; k <= radius; ++k)
    {
      w.push_back(std::exp(-0.5 * (k * spacing / 1.5) * (k * spacing / 1.5)));
      sum += w.back();
    }
    for (double & v : w)
    {
      v /= sum;
    }
    return w;
  };
  const std::vector<double> wx = axisWeights(0.5, 12); // 4 sigma = 12 pixels of 0.5 mm
  const std::vector<double> wy = axisWeights(2.0, 3);  // ceil(4 sigma / 2 mm) = 3 pixels
  double                    total = 0.0;
  for (int j = 0; j < 21; ++j)
  {
    for (int i = 0; i < 41; ++i)
    {
      const double value = impulse->GetPixel({ { i, j } });
      total += value;
      const int    di = i - 20;
      const int    dj = j - 10;
      const double expected = std::abs(di) <= 12 && std::abs(dj) <= 3 ? wx[di + 12] * wy[dj + 3] : 0.0;
      EXPECT_NEAR(value, expected, 1e-6) << "pixel " << i << ", " << j;
    }
  }
  EXPECT_NEAR(total, 1.0, 1e-5);

  FloatImageType::Pointer constant = make(7.0f);
  scratch = make(0.0f);
  itk::SmoothWithSampledGaussian<FloatImageType>(constant, scratch, 1.5, threader);
  for (int j = 0; j < 21; j += 5)
  {
    for (int i = 0; i < 41; i += 4)
    {
      EXPECT_NEAR(constant->GetPixel({ { i, j } }), 7.0f, 1e-5f) << "pixel " << i << ", " << j;
    }
  }
}

TEST(ExternalForceImageFilter, PointsTowardTheBoundaryAndIsNormalised)
{
  ImageType::SizeType size;
  size.Fill(48);
  ImageType::SpacingType spacing;
  spacing[0] = 0.8;
  spacing[1] = 1.0;
  spacing[2] = 1.2;
  ImageType::PointType origin;
  origin.Fill(-20.0);
  const double        axis[3] = { 0.6, 0.0, 0.8 };
  const DirectionType direction = Rotation(0.4, axis);
  auto                reference = ImageType::New();
  reference->SetSpacing(spacing);
  reference->SetOrigin(origin);
  reference->SetDirection(direction);
  itk::ContinuousIndex<double, 3> middle;
  middle.Fill(23.5);
  PointType center;
  reference->TransformContinuousIndexToPhysicalPoint(middle, center);
  const double                radius = 12.0;
  const itk::EllipsoidPhantom ball(center, itk::Vector<double, 3>(radius));
  // Intensity range in the thousands: the normalised field does not depend on it.
  const auto image = ball.MakeImage<itk::Image<float, 3>>(size, spacing, origin, direction, 3000.0f, -1000.0f);

  using FilterType = itk::ExternalForceImageFilter<itk::Image<float, 3>, ForceImageType>;
  auto filter = FilterType::New();
  filter->SetInput(image);
  filter->SetSigma(1.5);
  filter->Update();
  const ForceImageType * field = filter->GetOutput();
  EXPECT_EQ(field->GetSpacing(), spacing);
  EXPECT_EQ(field->GetDirection(), direction);

  double largest = 0.0;
  for (itk::ImageRegionConstIterator<ForceImageType> it(field, field->GetBufferedRegion()); !it.IsAtEnd(); ++it)
  {
    largest = std::max(largest, static_cast<double>(it.Get().GetNorm()));
  }
  EXPECT_NEAR(largest, 1.0, 1e-6);

  // Along any physical direction, 2 mm inside the force points outward and
  // 2 mm outside it points inward (radial, in physical space).
  const double directions[3][3] = { { 1, 0, 0 }, { 0, 0.6, 0.8 }, { -0.48, 0.6, -0.64 } };
  for (const auto & u : directions)
  {
    for (const double offset : { -2.0, 2.0 })
    {
      PointType p;
      for (unsigned int k = 0; k < 3; ++k)
      {
        p[k] = center[k] + (radius + offset) * u[k];
      }
      ForceImageType::IndexType index;
      ASSERT_TRUE(field->TransformPhysicalPointToIndex(p, index));
      const auto   f = field->GetPixel(index);
      const double radial = f[0] * u[0] + f[1] * u[1] + f[2] * u[2];
      EXPECT_GT(offset < 0 ? radial : -radial, 0.1) << "offset " << offset;
      EXPECT_LT(std::abs(radial), f.GetNorm() * 1.0001 + 1e-6);
      EXPECT_GT(std::abs(radial), 0.8 * f.GetNorm()) << "the force is mostly radial";
    }
  }

  filter->SetSigma(-1.0);
  EXPECT_NE(UpdateAndGetError(filter.GetPointer()).find("Sigma"), std::string::npos);
  filter->SetSigma(1.0);
  filter->UseGradientVectorFlowOn();
  filter->SetGradientVectorFlowRegularization(0.0);
  EXPECT_NE(UpdateAndGetError(filter.GetPointer()).find("GradientVectorFlowRegularization"), std::string::npos);
  std::ostringstream os;
  filter->Print(os);
  for (const char * member : { "Sigma: 1",
                               "NormalizeForces: On",
                               "UseGradientVectorFlow: On",
                               "GradientVectorFlowRegularization: 0",
                               "GradientVectorFlowIterations: 400" })
  {
    EXPECT_NE(os.str().find(member), std::string::npos) << member;
  }
}

TEST(ExternalForceImageFilter, ProgressRisesToOneWithGradientVectorFlow)
{
  const itk::EllipsoidPhantom ball(PointType(16.0), itk::Vector<double, 3>(8.0));
  ImageType::SizeType         size;
  size.Fill(32);
  const auto image = ball.MakeImage<itk::Image<float, 3>>(
    size, ImageType::SpacingType(1.0), PointType(0.0), DirectionType::GetIdentity(), 1.0f, 0.0f);
  using FilterType = itk::ExternalForceImageFilter<itk::Image<float, 3>, ForceImageType>;
  auto filter = FilterType::New();
  filter->SetInput(image);
  filter->UseGradientVectorFlowOn();
  filter->SetGradientVectorFlowIterations(20);
  std::vector<float> progress;
  filter->AddObserver(itk::ProgressEvent(),
                      [&](const itk::EventObject &) { progress.push_back(filter->GetProgress()); });
  filter->Update();
  ASSERT_GE(progress.size(), 20u);
  for (std::size_t k = 1; k < progress.size(); ++k)
  {
    EXPECT_GE(progress[k], progress[k - 1]) << "report " << k;
  }
  EXPECT_FLOAT_EQ(progress.back(), 1.0f);
}

// Issue 17 (2-D contours): the force field of a 2-D image, in physical
// space. A disk of radius 10 mm on a rotated grid of 0.5 x 0.8 mm pixels:
// 1.5 mm inside its edge the force points outward, 1.5 mm outside inward,
// radially; the normalised field peaks at 1. With gradient vector flow the
// field also reaches the disk's interior 6 mm from the edge (the plain
// gradient of a 1 mm Gaussian is below a thousandth there), still outward.
TEST(ExternalForceImageFilter, TwoDimensionalImageInPhysicalSpace)
{
  using Image2D = itk::Image<float, 2>;
  using Force2D = itk::Image<itk::CovariantVector<float, 2>, 2>;
  Image2D::SizeType size;
  size[0] = 64;
  size[1] = 40;
  Image2D::SpacingType spacing;
  spacing[0] = 0.5;
  spacing[1] = 0.8;
  Image2D::PointType origin;
  origin[0] = -3.0;
  origin[1] = 5.0;
  Image2D::DirectionType direction;
  const double           angle = 0.35;
  direction(0, 0) = std::cos(angle);
  direction(0, 1) = -std::sin(angle);
  direction(1, 0) = std::sin(angle);
  direction(1, 1) = std::cos(angle);
  auto image = Image2D::New();
  image->SetRegions(size);
  image->SetSpacing(spacing);
  image->SetOrigin(origin);
  image->SetDirection(direction);
  image->Allocate();
  itk::ContinuousIndex<double, 2> middle;
  middle[0] = 31.5;
  middle[1] = 19.5;
  Image2D::PointType center;
  image->TransformContinuousIndexToPhysicalPoint(middle, center);
  const double radius = 10.0;
  for (itk::ImageRegionIteratorWithIndex<Image2D> it(image, image->GetBufferedRegion()); !it.IsAtEnd(); ++it)
  {
    Image2D::PointType p;
    image->TransformIndexToPhysicalPoint(it.GetIndex(), p);
    it.Set(p.EuclideanDistanceTo(center) <= radius ? 200.0f : 20.0f);
  }

  using FilterType = itk::ExternalForceImageFilter<Image2D, Force2D>;
  for (const bool flow : { false, true })
  {
    auto filter = FilterType::New();
    filter->SetInput(image);
    filter->SetSigma(1.0);
    filter->SetUseGradientVectorFlow(flow);
    filter->Update();
    const Force2D * field = filter->GetOutput();
    EXPECT_EQ(field->GetDirection(), direction);
    double largest = 0.0;
    for (itk::ImageRegionConstIterator<Force2D> it(field, field->GetBufferedRegion()); !it.IsAtEnd(); ++it)
    {
      largest = std::max(largest, static_cast<double>(it.Get().GetNorm()));
    }
    EXPECT_NEAR(largest, 1.0, 1e-6);

    const auto forceAt = [&](double angleOnCircle, double distanceFromCenter) {
      Image2D::PointType p;
      p[0] = center[0] + distanceFromCenter * std::cos(angleOnCircle);
      p[1] = center[1] + distanceFromCenter * std::sin(angleOnCircle);
      Force2D::IndexType index;
      EXPECT_TRUE(field->TransformPhysicalPointToIndex(p, index));
      const auto f = field->GetPixel(index);
      return std::make_pair(f[0] * std::cos(angleOnCircle) + f[1] * std::sin(angleOnCircle),
                            static_cast<double>(f.GetNorm()));
    };
    for (const double a : { 0.0, 1.1, 2.5, 4.0, 5.3 })
    {
      const auto inside = forceAt(a, radius - 1.5);
      const auto outside = forceAt(a, radius + 1.5);
      EXPECT_GT(inside.first, 0.1) << "outward inside, angle " << a << (flow ? ", GVF" : "");
      EXPECT_LT(outside.first, -0.1) << "inward outside, angle " << a << (flow ? ", GVF" : "");
      EXPECT_GT(inside.first, 0.8 * inside.second) << "radial, angle " << a;
      const auto deep = forceAt(a, radius - 6.0);
      if (flow)
      {
        EXPECT_GT(deep.first, 0.8 * deep.second) << "GVF reaches 6 mm inside, outward, angle " << a;
        EXPECT_GT(deep.second, 1e-3) << "angle " << a;
      }
      else
      {
        EXPECT_LT(deep.second, 1e-3) << "angle " << a;
      }
    }
  }
}
