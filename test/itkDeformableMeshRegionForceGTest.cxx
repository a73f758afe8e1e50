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

// The region force of DeformableMeshFilter: its intensity model (known
// answers of the estimate) and a surface that stops on an object's boundary
// by itself, for a bright object on a dark background and the reverse.

#include "itkDeformableMeshFilter.h"
#include "itkEllipsoidPhantom.h"

#include "itkSmoothingRecursiveGaussianImageFilter.h"

#include "gtest/gtest.h"

#include <cmath>
#include <algorithm>
#include <cstdint>
#include <limits>
#include <random>
#include <vector>

namespace
{
using MeshType = itk::Mesh<double, 3>;
using ImageType = itk::Image<float, 3>;
using ForceImageType = itk::Image<itk::CovariantVector<float, 3>, 3>;
using FilterType = itk::DeformableMeshFilter<MeshType, ForceImageType>;

constexpr double Radius = 12.0; // mm, of the ball
constexpr double Centre = 23.5; // mm, on each axis

/** A 48^3 image (spacing 1) holding a ball of radius Radius: inside and
 * outside values given. */
ImageType::Pointer
MakeBall(float inside, float outside)
{
  auto                  image = ImageType::New();
  ImageType::RegionType region;
  region.SetSize({ { 48, 48, 48 } });
  image->SetRegions(region);
  image->Allocate();
  for (itk::ImageRegionIteratorWithIndex<ImageType> it(image, region); !it.IsAtEnd(); ++it)
  {
    double squared = 0.0;
    for (unsigned int k = 0; k < 3; ++k)
    {
      squared += (it.GetIndex()[k] - Centre) * (it.GetIndex()[k] - Centre);
    }
    it.Set(squared <= Radius * Radius ? inside : outside);
  }
  return image;
}

ForceImageType::Pointer
MakeZeroForces(const ImageType * like)
{
  auto forces = ForceImageType::New();
  forces->CopyInformation(like);
  forces->SetRegions(like->GetLargestPossibleRegion());
  forces->Allocate();
  forces->FillBuffer(itk::CovariantVector<float, 3>(0.0f));
  return forces;
}

/** Mean and largest |distance to the centre - Radius| of the output. */
void
RadialError(const MeshType * mesh, double & mean, double & maximum)
{
  mean = 0.0;
  maximum = 0.0;
  for (auto it = mesh->GetPoints()->Begin(); it != mesh->GetPoints()->End(); ++it)
  {
    double squared = 0.0;
    for (unsigned int k = 0; k < 3; ++k)
    {
      squared += (it.Value()[k] - Centre) * (it.Value()[k] - Centre);
    }
    const double error = std::abs(std::sqrt(squared) - Radius);
    mean += error;
    maximum = std::max(maximum, error);
  }
  mean /= static_cast<double>(mesh->GetNumberOfPoints());
}

/** The region force alone (no external force, full umbrella elasticity and
 * a little rigidity), from a sphere of the given radius at the ball's
 * centre. */
FilterType::Pointer
MakeFilter(const ImageType * image, unsigned int iterations, double radius = 5.0)
{
  MeshType::PointType centre;
  centre.Fill(Centre);
  auto filter = FilterType::New();
  filter->SetInput(itk::MakeSphereMesh<MeshType>(centre, radius, 4));
  filter->SetForceImage(MakeZeroForces(image));
  filter->SetIntensityImage(image);
  filter->SetScaleFactor(0.0);
  filter->SetRegionWeight(0.25);
  filter->SetElasticity(0.3);
  filter->SetTangentialElasticity(false);
  filter->SetRigidity(0.05);
  filter->SetNumberOfIterations(iterations);
  return filter;
}

} // namespace

TEST(DeformableMeshRegionForce, EstimateFromRobustStatistics)
{
  // Median 10 and median absolute deviation 1: spread 1.4826.
  itk::DeformableMeshFilterDetail::RegionForce model;
  ASSERT_TRUE(model.Estimate({ 8.0, 9.0, 10.0, 11.0, 12.0, 9.5, 10.5 }, 2.5, 9.0, 11.0));
  EXPECT_NEAR(model.GetLower(), 10.0 - 2.5 * 1.4826, 1e-12);
  EXPECT_NEAR(model.GetUpper(), 10.0 + 2.5 * 1.4826, 1e-12);
  EXPECT_NEAR(model.GetWidth(), 0.5 * 1.4826, 1e-12);
  // Inside the range: inflation, at most 1; on a bound: 0; beyond: deflation.
  EXPECT_DOUBLE_EQ(model.Speed(10.0), 1.0);
  EXPECT_NEAR(model.Speed(model.GetLower()), 0.0, 1e-12);
  EXPECT_NEAR(model.Speed(model.GetUpper() + 0.25 * 1.4826), -0.5, 1e-12);
  EXPECT_DOUBLE_EQ(model.Speed(-1000.0), -1.0);
  EXPECT_DOUBLE_EQ(model.Speed(std::nan("")), -1.0); // outside the image

  // No spread (a piecewise constant object): the bound lies halfway to the
  // image's farther extreme.
  // A spread below a fifth of the image's range counts as none.
  ASSERT_TRUE(model.Estimate({ 9.9, 10.0, 10.1 }, 2.5, 0.0, 10.0));
  EXPECT_DOUBLE_EQ(model.GetLower(), 5.0);
  ASSERT_TRUE(model.Estimate({ 1.0, 1.0, 1.0 }, 2.5, 0.0, 1.0));
  EXPECT_DOUBLE_EQ(model.GetLower(), 0.5);
  EXPECT_DOUBLE_EQ(model.GetUpper(), 1.5);
  EXPECT_DOUBLE_EQ(model.GetWidth(), 0.0625);
  EXPECT_FALSE(model.Estimate({}, 2.5, 0.0, 1.0));
}

TEST(DeformableMeshRegionForce, SelectRankIsTheValueOfThatRank)
{
  // SelectRank against std::nth_element: random values, plateaus (a binary
  // image's few distinct values), sorted and reversed arrays, sizes around
  // the subsample's threshold, ranks at both ends and in between; and a
  // case whose subsample misses the rank's neighbourhood (the fallback).
  using itk::DeformableMeshFilterDetail::SelectRank;
  std::mt19937                          random(7);
  std::uniform_real_distribution<float> uniform(-100.0f, 100.0f);
  const auto                            reference = [](std::vector<float> v, size_t k) {
    std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(k), v.end());
    return v[k];
  };
  for (const size_t n : { size_t{ 1 }, size_t{ 1023 }, size_t{ 1024 }, size_t{ 5000 }, size_t{ 16384 } })
  {
    for (int kind = 0; kind < 4; ++kind)
    {
      std::vector<float> values(n);
      for (float & v : values)
      {
        v = kind == 1 ? (uniform(random) < 20.0f ? 200.0f : 40.0f) : uniform(random);
      }
      if (kind == 2)
      {
        std::sort(values.begin(), values.end());
      }
      if (kind == 3)
      {
        std::sort(values.rbegin(), values.rend());
      }
      for (const double q : { 0.0, 0.02, 0.5, 0.98, 0.99, 1.0 })
      {
        const auto         k = static_cast<size_t>(q * static_cast<double>(n - 1));
        std::vector<float> copy = values;
        EXPECT_EQ(SelectRank(copy, k), reference(values, k)) << "n " << n << " kind " << kind << " q " << q;
      }
    }
  }
  // Every sixteenth value (the subsample) 0, the others 1 to n: the bracket
  // from the subsample holds no value of rank n / 2.
  std::vector<double> skewed(4096);
  for (size_t i = 0; i < skewed.size(); ++i)
  {
    skewed[i] = i % 16 == 8 ? 0.0 : static_cast<double>(i + 1);
  }
  std::vector<double> sorted = skewed;
  std::sort(sorted.begin(), sorted.end());
  for (const size_t k : { size_t{ 0 }, size_t{ 255 }, size_t{ 256 }, size_t{ 2048 }, size_t{ 4095 } })
  {
    std::vector<double> copy = skewed;
    EXPECT_EQ(SelectRank(copy, k), sorted[k]) << "k " << k;
  }
  // Infinities at both ends (ranks among them and next to them).
  std::vector<float> infinite(5000);
  for (size_t i = 0; i < infinite.size(); ++i)
  {
    infinite[i] = i % 50 == 0   ? -std::numeric_limits<float>::infinity()
                  : i % 50 == 1 ? std::numeric_limits<float>::infinity()
                                : uniform(random);
  }
  for (const size_t k :
       { size_t{ 0 }, size_t{ 99 }, size_t{ 100 }, size_t{ 2500 }, size_t{ 4899 }, size_t{ 4900 }, size_t{ 4999 } })
  {
    std::vector<float> copy = infinite;
    EXPECT_EQ(SelectRank(copy, k), reference(infinite, k)) << "k " << k;
  }
}

TEST(DeformableMeshRegionForce, BackgroundMovesTheBoundsHalfwayToIt)
{
  itk::DeformableMeshFilterDetail::RegionForce model;
  // Median 100, spread 10, tolerance 2: the object's class is [80, 120]
  // (its half-width, 20, above a fifth of the image's range [60, 140]).
  ASSERT_TRUE(model.SetModel(100.0, 10.0, 2.0, 60.0, 140.0));
  EXPECT_DOUBLE_EQ(model.GetLower(), 80.0);
  EXPECT_DOUBLE_EQ(model.GetUpper(), 120.0);
  std::vector<double> samples(400, 100.0);
  samples.resize(460, 20.0);  // 60 dark samples (13 %), median 20
  samples.resize(470, 150.0); // 10 bright ones (2 %): too few to count
  model.AdaptToBackground(samples);
  EXPECT_DOUBLE_EQ(model.GetLower(), 60.0);
  EXPECT_DOUBLE_EQ(model.GetUpper(), 120.0);
  samples.resize(520, 180.0); // 60 bright ones, median 180
  model.AdaptToBackground(samples);
  EXPECT_DOUBLE_EQ(model.GetLower(), 60.0);
  EXPECT_DOUBLE_EQ(model.GetUpper(), 140.0);
  // The surface inside the object again: the bounds return to the class's.
  model.AdaptToBackground(std::vector<double>(100, 101.0));
  EXPECT_DOUBLE_EQ(model.GetLower(), 80.0);
  EXPECT_DOUBLE_EQ(model.GetUpper(), 120.0);
}

TEST(DeformableMeshRegionForce, BackgroundPutsTheBoundOnTheEdge)
{
  // A ball of 100 on 20, with the object's model given as median 100 and
  // spread 20 (tolerance 1): the class's lower bound is 80, which the
  // smoothed edge (sigma 1 mm) crosses 0.67 mm inside the ball (the normal
  // quantile of (80 - 20) / 80). The background (20) moves the bound to 60,
  // halfway, where the smoothed edge is on the ball's boundary.
  const ImageType::Pointer image = MakeBall(100.0f, 20.0f);
  double                   means[2];
  for (int background = 0; background < 2; ++background)
  {
    const FilterType::Pointer filter = MakeFilter(image, 800);
    filter->SetIntensityTolerance(1.0);
    filter->SetObjectIntensityStatistics(100.0, 20.0);
    filter->SetEstimateBackgroundIntensity(background != 0);
    filter->Update();
    EXPECT_FALSE(filter->GetEstimateObjectIntensityRange());
    EXPECT_DOUBLE_EQ(filter->GetObjectIntensityMedian(), 100.0);
    // (The samples a voxel outside the ball still see its smoothed edge: 61.)
    EXPECT_NEAR(filter->GetObjectIntensityLower(), background != 0 ? 60.0 : 80.0, 1.5);
    double maximum;
    RadialError(filter->GetOutput(), means[background], maximum);
    if (background != 0)
    {
      EXPECT_LT(maximum, 0.5);
    }
  }
  EXPECT_GT(means[0], 0.5) << "without the background the surface stops inside the edge";
  EXPECT_LT(means[1], 0.25);
}

TEST(DeformableMeshRegionForce, BrightBallStopsOnItsBoundaryByItself)
{
  const ImageType::Pointer image = MakeBall(100.0f, 20.0f);
  double                   means[2];
  unsigned int             k = 0;
  for (unsigned int iterations : { 500u, 2000u })
  {
    const FilterType::Pointer filter = MakeFilter(image, iterations);
    filter->Update();
    // Estimated inside the initial sphere: the object's value, the bound
    // halfway to the background (60; 61 from the background's samples a
    // voxel outside the ball, which still see its smoothed edge).
    EXPECT_NEAR(filter->GetObjectIntensityLower(), 60.0, 1.5);
    double maximum;
    RadialError(filter->GetOutput(), means[k], maximum);
    EXPECT_LT(means[k], 0.25) << iterations << " iterations";
    EXPECT_LT(maximum, 0.5) << iterations << " iterations";
    ++k;
  }
  // It stopped: four times as many iterations give the same surface.
  EXPECT_NEAR(means[0], means[1], 0.02);
}

TEST(DeformableMeshRegionForce, DarkBallOnBrightBackground)
{
  const FilterType::Pointer filter = MakeFilter(MakeBall(-300.0f, 900.0f), 800);
  filter->Update();
  EXPECT_NEAR(filter->GetObjectIntensityUpper(), 300.0, 10.0);
  double mean;
  double maximum;
  RadialError(filter->GetOutput(), mean, maximum);
  EXPECT_LT(mean, 0.25);
  EXPECT_LT(maximum, 0.5);
}

TEST(DeformableMeshEdgeSearch, FindsTheStrongestEdgeOfItsPolarity)
{
  // A bright ball (radius 12) on a dark background, smoothed by the filter
  // (RegionSigma 1): from a point 1.5 mm inside the boundary along the
  // outward normal, the falling edge is 1.5 mm out; the search of the other
  // polarity finds none (the profile only falls), nor does a search whose
  // minimum contrast is above the ball's.
  const ImageType::Pointer image = MakeBall(100.0f, 20.0f);
  using SmoothingType = itk::SmoothingRecursiveGaussianImageFilter<ImageType, ImageType>;
  auto smoothing = SmoothingType::New();
  smoothing->SetInput(image);
  smoothing->SetSigma(1.0);
  smoothing->Update();
  itk::DeformableMeshFilterDetail::IntensitySampler sampler;
  sampler.SetImage(smoothing->GetOutput());
  const double                                x[3] = { Centre + Radius - 1.5, Centre, Centre };
  const float                                 n[3] = { 1.0f, 0.0f, 0.0f };
  itk::DeformableMeshFilterDetail::EdgeSearch search;
  search.Configure(3.0, 0.5, 1.0, 1, 10.0);
  EXPECT_EQ(search.GetDistance(), 3.0);
  // The binary ball's boundary on this axis lies between the voxel centres
  // 35 and 36, at Centre + Radius.
  EXPECT_NEAR(search.Find(sampler, x, n), 1.5, 0.1);
  search.Configure(3.0, 0.5, 1.0, -1, 10.0);
  EXPECT_TRUE(std::isnan(search.Find(sampler, x, n)));
  search.Configure(3.0, 0.5, 1.0, 1, 90.0);
  EXPECT_TRUE(std::isnan(search.Find(sampler, x, n)));
  // Beyond the search distance: no edge.
  const double far[3] = { Centre + Radius - 6.0, Centre, Centre };
  search.Configure(3.0, 0.5, 1.0, 1, 10.0);
  EXPECT_TRUE(std::isnan(search.Find(sampler, far, n)));
}

TEST(DeformableMeshEdgeSearch, EdgeSearchAloneSettlesOnTheBoundary)
{
  // The edge search alone (no region force), from a sphere of radius 10 in
  // the ball of radius 12, for a bright and a dark ball (polarity from the
  // intensity model): the surface stops on the boundary, the same after 300
  // and 1200 iterations. The binary boundary lies half a voxel beyond the
  // last voxel inside: mean error measured against Radius + 0.5.
  for (const float inside : { 100.0f, -300.0f })
  {
    const ImageType::Pointer image = MakeBall(inside, inside > 0.0f ? 20.0f : 900.0f);
    double                   means[2];
    unsigned int             k = 0;
    for (unsigned int iterations : { 300u, 1200u })
    {
      MeshType::PointType centre;
      centre.Fill(Centre);
      const FilterType::Pointer filter = MakeFilter(image, iterations, 10.0);
      filter->SetRegionWeight(0.0);
      filter->SetEdgeSearchWeight(0.25);
      filter->SetEdgeSearchDistance(3.0);
      filter->Update();
      EXPECT_EQ(filter->GetNumberOfEdgeHits(), filter->GetOutput()->GetNumberOfPoints());
      double sum = 0.0;
      double largest = 0.0;
      for (auto it = filter->GetOutput()->GetPoints()->Begin(); it != filter->GetOutput()->GetPoints()->End(); ++it)
      {
        const double error = it.Value().EuclideanDistanceTo(centre) - Radius;
        sum += std::abs(error);
        largest = std::max(largest, std::abs(error));
      }
      means[k] = sum / filter->GetOutput()->GetNumberOfPoints();
      EXPECT_LT(means[k], 0.25) << inside << ", " << iterations << " iterations";
      EXPECT_LT(largest, 0.5) << inside << ", " << iterations << " iterations";
      ++k;
    }
    EXPECT_NEAR(means[0], means[1], 0.02) << inside;
  }
}

TEST(DeformableMeshEdgeSearch, BadParameters)
{
  const ImageType::Pointer  image = MakeBall(100.0f, 20.0f);
  const FilterType::Pointer filter = MakeFilter(image, 5);
  filter->SetEdgeSearchWeight(-1.0);
  EXPECT_THROW(filter->Update(), itk::ExceptionObject);
  filter->SetEdgeSearchWeight(std::nan(""));
  EXPECT_THROW(filter->Update(), itk::ExceptionObject);
  filter->SetEdgeSearchWeight(0.25);
  filter->SetEdgeSearchDistance(0.0);
  EXPECT_THROW(filter->Update(), itk::ExceptionObject);
  filter->SetEdgeSearchDistance(2.0);
  EXPECT_NO_THROW(filter->Update());
  filter->SetEdgePolarity(5);
  EXPECT_EQ(filter->GetEdgePolarity(), 1);
}

TEST(DeformableMeshRegionForce, GivenRangeAndBadParameters)
{
  const ImageType::Pointer  image = MakeBall(100.0f, 20.0f);
  const FilterType::Pointer filter = MakeFilter(image, 600);
  // A bound at 80 instead of the estimate's 60: the smoothed edge crosses it
  // 0.67 sigma inside the ball (the normal quantile of 0.75).
  filter->SetObjectIntensityRange(80.0, 1000.0, 10.0);
  filter->Update();
  EXPECT_FALSE(filter->GetEstimateObjectIntensityRange());
  double mean;
  double maximum;
  RadialError(filter->GetOutput(), mean, maximum);
  EXPECT_LT(mean, 1.0);

  const FilterType::Pointer noImage = MakeFilter(image, 10);
  noImage->SetIntensityImage(nullptr);
  EXPECT_THROW(noImage->Update(), itk::ExceptionObject);
  const FilterType::Pointer badSigma = MakeFilter(image, 10);
  badSigma->SetRegionSigma(-1.0);
  EXPECT_THROW(badSigma->Update(), itk::ExceptionObject);
  const FilterType::Pointer badWeight = MakeFilter(image, 10);
  badWeight->SetRegionWeight(std::nan(""));
  EXPECT_THROW(badWeight->Update(), itk::ExceptionObject);
  const FilterType::Pointer badRange = MakeFilter(image, 10);
  badRange->SetObjectIntensityRange(5.0, 1.0, 1.0);
  EXPECT_THROW(badRange->Update(), itk::ExceptionObject);
  const FilterType::Pointer badStatistics = MakeFilter(image, 10);
  badStatistics->SetObjectIntensityStatistics(100.0, -1.0);
  EXPECT_THROW(badStatistics->Update(), itk::ExceptionObject);
  const FilterType::Pointer badInterval = MakeFilter(image, 10);
  badInterval->SetBackgroundUpdateInterval(0);
  EXPECT_THROW(badInterval->Update(), itk::ExceptionObject);
}
