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

// Segmentation quality of DeformableMeshFilter on the seed paper's own case:
// a sphere of radius 16 voxels inside a 64^3 binary ellipsoid of radii
// (18, 14, 28) centred at voxel (31, 31, 31). The poles along z are 12 voxels
// away from the sphere, beyond the capture range of plain gradient forces: the
// balloon force or gradient vector flow must bring the mesh there. Known
// answers: distances to the analytic ellipsoid, triangle orientation against
// the ellipsoid's normal, triangle angles.

#include "itkAdditiveGaussianNoiseImageFilter.h"
#include "itkBinaryMask3DMeshSource.h"
#include "itkDeformableMeshFilter.h"
#include "itkEllipsoidPhantom.h"
#include "itkExternalForceImageFilter.h"
#include "itkImageRegionIteratorWithIndex.h"
#include "itkLineCell.h"
#include "itkMesh.h"
#include "itkQuadrilateralCell.h"
#include "itkTriangleCell.h"

#include "gtest/gtest.h"

#include <array>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <set>
#include <sstream>
#include <string>

namespace
{
constexpr unsigned int Dimension = 3;
using MeshType =
  itk::Mesh<double, Dimension, itk::DefaultStaticMeshTraits<double, Dimension, Dimension, double, double, double>>;
using PointType = MeshType::PointType;
using ImageType = itk::Image<float, Dimension>;
using ForceImageType = itk::Image<itk::CovariantVector<float, Dimension>, Dimension>;
using DirectionType = ImageType::DirectionType;
using FilterType = itk::DeformableMeshFilter<MeshType, ForceImageType>;

enum class Capture
{
  Balloon,
  GradientVectorFlow,
  Region // the region force on the image's intensities, no balloon
};

struct Geometry
{
  ImageType::SizeType    size;
  ImageType::SpacingType spacing;
  ImageType::PointType   origin;
  DirectionType          direction;
  double                 voxel; // the smallest spacing: the unit of the tolerances
  double                 scale; // the physical size of the seed's voxel: the object's scale
  double                 sigma; // Gaussian smoothing of the force field with the balloon, physical units
};

/** Gradient vector flow brings the capture range itself: it needs less
 * smoothing than the balloon, which relies on the smoothed edge to stop. */
double
SigmaFor(const Geometry & g, Capture capture)
{
  return capture == Capture::GradientVectorFlow ? 0.8 * g.sigma : g.sigma;
}

/** Unit voxels, 64^3, identity direction: the seed's case. */
Geometry
VoxelGeometry()
{
  Geometry g;
  g.size.Fill(64);
  g.spacing.Fill(1.0);
  g.origin.Fill(0.0);
  g.direction.SetIdentity();
  g.voxel = 1.0;
  g.scale = 1.0;
  g.sigma = 1.0;
  return g;
}

/** The same physical object (radii (18, 14, 28) mm) imaged with spacing
 * (0.6, 0.6, 2.0), a non-zero origin and a rotated direction; tolerances in
 * units of the smallest spacing. */
Geometry
AnisotropicGeometry()
{
  Geometry g;
  g.size[0] = 100;
  g.size[1] = 100;
  g.size[2] = 32;
  g.spacing[0] = 0.6;
  g.spacing[1] = 0.6;
  g.spacing[2] = 2.0;
  g.origin[0] = 10.0;
  g.origin[1] = -25.0;
  g.origin[2] = 4.0;
  // Rotation of 0.6 rad about the unit axis (2, 1, 2) / 3.
  const double u[3] = { 2.0 / 3.0, 1.0 / 3.0, 2.0 / 3.0 };
  const double c = std::cos(0.6);
  const double s = std::sin(0.6);
  for (unsigned int i = 0; i < 3; ++i)
  {
    for (unsigned int j = 0; j < 3; ++j)
    {
      g.direction(i, j) = (i == j ? c : 0.0) + (1.0 - c) * u[i] * u[j];
    }
  }
  g.direction(0, 1) -= s * u[2];
  g.direction(0, 2) += s * u[1];
  g.direction(1, 0) += s * u[2];
  g.direction(1, 2) -= s * u[0];
  g.direction(2, 0) -= s * u[1];
  g.direction(2, 1) += s * u[0];
  g.voxel = 0.6;
  g.scale = 1.0;
  g.sigma = 1.0;
  return g;
}

struct Result
{
  double              meanDistance{ 0.0 };
  double              maximumDistance{ 0.0 };
  double              minimumAngle{ 180.0 };
  unsigned int        flippedTriangles{ 0 };
  unsigned long       iterations{ 0 };
  bool                converged{ false };
  std::vector<double> meanDistanceHistory;    // after each iteration
  std::vector<double> maximumDistanceHistory; // after each iteration
};

class SegmentationCase
{
public:
  SegmentationCase(const Geometry & geometry, double noiseFraction)
    : m_Geometry(geometry)
  {
    // The ellipsoid: centre at voxel (31, 31, 31) of the seed's grid, i.e. the
    // middle of the image, semi-axes (18, 14, 28) voxels of the smallest
    // spacing, along the image axes.
    auto reference = ImageType::New();
    reference->SetSpacing(geometry.spacing);
    reference->SetOrigin(geometry.origin);
    reference->SetDirection(geometry.direction);
    itk::ContinuousIndex<double, 3> centerIndex;
    for (unsigned int k = 0; k < 3; ++k)
    {
      centerIndex[k] = geometry.size[k] == 64 ? 31.0 : 0.5 * (geometry.size[k] - 1.0);
    }
    reference->TransformContinuousIndexToPhysicalPoint(centerIndex, m_Center);
    itk::EllipsoidPhantom::VectorType radii;
    radii[0] = 18.0 * geometry.scale;
    radii[1] = 14.0 * geometry.scale;
    radii[2] = 28.0 * geometry.scale;
    itk::EllipsoidPhantom::MatrixType axes;
    axes = geometry.direction;
    m_Ellipsoid = std::make_unique<itk::EllipsoidPhantom>(m_Center, radii, axes);

    // Contrast 100 on a background of 0, optionally with Gaussian noise.
    m_Image = m_Ellipsoid->MakeImage<ImageType>(
      geometry.size, geometry.spacing, geometry.origin, geometry.direction, 100.0f, 0.0f);
    if (noiseFraction > 0.0)
    {
      auto noise = itk::AdditiveGaussianNoiseImageFilter<ImageType>::New();
      noise->SetInput(m_Image);
      noise->SetStandardDeviation(100.0 * noiseFraction);
      noise->SetSeed(20261121);
      noise->Update();
      m_Image = noise->GetOutput();
      m_Image->DisconnectPipeline();
    }
    m_Sphere = itk::MakeSphereMesh<MeshType>(m_Center, 16.0 * geometry.scale, 4);
  }

  ForceImageType::Pointer
  Forces(Capture capture) const
  {
    auto forces = itk::ExternalForceImageFilter<ImageType, ForceImageType>::New();
    forces->SetInput(m_Image);
    forces->SetSigma(SigmaFor(m_Geometry, capture));
    forces->SetUseGradientVectorFlow(capture == Capture::GradientVectorFlow);
    // Less regularisation, diffused longer (same reach): the field follows
    // the high-curvature poles more closely than with the defaults.
    forces->SetGradientVectorFlowRegularization(0.05);
    forces->SetGradientVectorFlowIterations(800);
    forces->Update();
    ForceImageType::Pointer field = forces->GetOutput();
    field->DisconnectPipeline();
    return field;
  }

  /** The recommended parameter set (the same for every case, in voxels). */
  FilterType::Pointer
  MakeFilter(const ForceImageType * forces, Capture capture, unsigned long iterations) const
  {
    auto filter = FilterType::New();
    filter->SetInput(m_Sphere);
    filter->SetForceImage(forces);
    filter->SetScaleFactor(0.5 * SigmaFor(m_Geometry, capture));
    filter->SetElasticity(0.3);
    filter->SetRigidity(0.05);
    filter->SetBalloon(capture == Capture::Balloon ? 0.1 * m_Geometry.sigma : 0.0);
    if (capture == Capture::Region)
    {
      filter->SetIntensityImage(m_Image);
      filter->SetRegionWeight(0.25 * m_Geometry.voxel);
    }
    filter->SetNumberOfIterations(iterations);
    return filter;
  }

  Result
  Measure(FilterType * filter) const
  {
    Result           r;
    const MeshType * mesh = filter->GetOutput();
    m_Ellipsoid->MeasureDistance(mesh, r.meanDistance, r.maximumDistance);
    r.iterations = filter->GetCurrentIteration();
    r.converged = filter->GetConverged();
    constexpr double degrees = 180.0 / 3.14159265358979323846;
    for (auto it = mesh->GetCells()->Begin(); it != mesh->GetCells()->End(); ++it)
    {
      const auto * ids = it.Value()->PointIdsBegin();
      PointType    p[3];
      for (unsigned int k = 0; k < 3; ++k)
      {
        p[k] = mesh->GetPoint(ids[k]);
      }
      for (unsigned int k = 0; k < 3; ++k)
      {
        const auto   u = p[(k + 1) % 3] - p[k];
        const auto   v = p[(k + 2) % 3] - p[k];
        const double cosine = (u * v) / (u.GetNorm() * v.GetNorm());
        r.minimumAngle = std::min(r.minimumAngle, std::acos(std::max(-1.0, std::min(1.0, cosine))) * degrees);
      }
      // Flipped: the triangle's outward normal (orientation made outward by
      // the filter's sign) against the ellipsoid's outward normal there.
      PointType centroid;
      for (unsigned int k = 0; k < 3; ++k)
      {
        centroid[k] = (p[0][k] + p[1][k] + p[2][k]) / 3.0;
      }
      const auto             local = m_Ellipsoid->ToLocal(centroid);
      itk::Vector<double, 3> gradient;
      gradient.Fill(0.0);
      for (unsigned int k = 0; k < 3; ++k)
      {
        const double g = local[k] / (m_Ellipsoid->GetRadii()[k] * m_Ellipsoid->GetRadii()[k]);
        for (unsigned int j = 0; j < 3; ++j)
        {
          gradient[j] += m_Ellipsoid->GetAxes()(j, k) * g;
        }
      }
      const auto normal = itk::CrossProduct(p[1] - p[0], p[2] - p[0]) * filter->GetOrientationSign();
      if (normal * gradient <= 0.0)
      {
        ++r.flippedTriangles;
      }
    }
    return r;
  }

  Result
  Run(Capture capture, unsigned long iterations, double convergenceTolerance = 0.0, bool history = false) const
  {
    const auto forces = this->Forces(capture);
    auto       filter = this->MakeFilter(forces, capture, iterations);
    filter->SetConvergenceTolerance(convergenceTolerance * m_Geometry.voxel);
    std::vector<double> meanHistory;
    std::vector<double> maximumHistory;
    if (history)
    {
      filter->AddObserver(itk::IterationEvent(), [&](const itk::EventObject &) {
        double mean = 0.0;
        double maximum = 0.0;
        m_Ellipsoid->MeasureDistance(filter->GetOutput(), mean, maximum);
        meanHistory.push_back(mean);
        maximumHistory.push_back(maximum);
      });
    }
    filter->Update();
    Result r = this->Measure(filter);
    r.meanDistanceHistory = meanHistory;
    r.maximumDistanceHistory = maximumHistory;
    return r;
  }

  /** The recommended parameters from a sphere of \a resolution
   * (itk::MakeSphereMesh(): 4^(resolution + 1) + 2 vertices) with
   * ReferenceEdgeLength \a referenceEdgeLength voxels (0: none), the
   * balloon of \a capture when \a balloon. */
  Result
  RunAtResolution(const ForceImageType * forces,
                  Capture                capture,
                  unsigned long          iterations,
                  unsigned int           resolution,
                  double                 referenceEdgeLength,
                  bool                   balloon = true) const
  {
    const auto sphere = itk::MakeSphereMesh<MeshType>(m_Center, 16.0 * m_Geometry.scale, resolution);
    auto       filter = this->MakeFilter(forces, capture, iterations);
    filter->SetInput(sphere);
    filter->SetReferenceEdgeLength(referenceEdgeLength * m_Geometry.voxel);
    if (!balloon)
    {
      filter->SetBalloon(0.0);
    }
    filter->Update();
    return this->Measure(filter);
  }

  double
  Voxel() const
  {
    return m_Geometry.voxel;
  }

private:
  Geometry                               m_Geometry;
  PointType                              m_Center;
  std::unique_ptr<itk::EllipsoidPhantom> m_Ellipsoid;
  ImageType::Pointer                     m_Image;
  MeshType::Pointer                      m_Sphere;
};

void
Report(const char * name, const Result & r, double voxel)
{
  std::cout << name << ": mean " << r.meanDistance / voxel << " voxel, max " << r.maximumDistance / voxel
            << " voxel, min angle " << r.minimumAngle << " deg, flipped " << r.flippedTriangles << ", " << r.iterations
            << " iterations" << (r.converged ? " (converged)" : "") << std::endl;
}

void
ExpectQuality(const Result & r, double voxel, double meanTolerance, double maximumTolerance)
{
  EXPECT_LE(r.meanDistance, meanTolerance * voxel);
  if (maximumTolerance > 0.0)
  {
    EXPECT_LE(r.maximumDistance, maximumTolerance * voxel);
  }
  EXPECT_EQ(r.flippedTriangles, 0u);
  EXPECT_GE(r.minimumAngle, 15.0);
}
} // namespace

// The measure itself: known distances to the ellipsoid of radii (18, 14, 28),
// including points inside on its long axis, whose closest points form a ring
// around that axis (x = 784 z / 588 along it, the rest on the shortest axis),
// and no distance above that to the nearest of 720 000 points of its surface.
TEST(SegmentationQuality, EllipsoidDistanceKnownAnswers)
{
  PointType center;
  center.Fill(0.0);
  itk::EllipsoidPhantom::VectorType radii;
  radii[0] = 18.0;
  radii[1] = 14.0;
  radii[2] = 28.0;
  const itk::EllipsoidPhantom ellipsoid(center, radii);
  const auto                  at = [](double x, double y, double z) {
    PointType p;
    p[0] = x;
    p[1] = y;
    p[2] = z;
    return p;
  };
  EXPECT_NEAR(ellipsoid.DistanceToSurface(at(0, 0, 0)), 14.0, 1e-9);
  EXPECT_NEAR(ellipsoid.DistanceToSurface(at(0, 0, 30)), 2.0, 1e-9);
  EXPECT_NEAR(ellipsoid.DistanceToSurface(at(20, 0, 0)), 2.0, 1e-9);
  EXPECT_NEAR(ellipsoid.DistanceToSurface(at(0, 0, -26)), 2.0, 1e-9);
  {
    // On the 18-axis near the centre: the ring around that axis too.
    const double x = 324.0 * 3.0 / 128.0;
    EXPECT_NEAR(ellipsoid.DistanceToSurface(at(3, 0, 0)),
                std::hypot(x - 3.0, 14.0 * std::sqrt(1.0 - (x / 18.0) * (x / 18.0))),
                1e-9);
  }
  for (const double zc : { 16.0, 8.0, -12.0 })
  {
    const double x = 784.0 * std::abs(zc) / 588.0;
    const double ring = 14.0 * std::sqrt(1.0 - (x / 28.0) * (x / 28.0));
    EXPECT_NEAR(ellipsoid.DistanceToSurface(at(0, 0, zc)), std::hypot(x - std::abs(zc), ring), 1e-9) << zc;
  }
  EXPECT_NEAR(ellipsoid.DistanceToSurface(at(0, 0, 16)), 10.5198, 1e-4);

  // Against a dense sampling of the surface: never above it, within its
  // sampling error (0.15 mm between samples) below it.
  std::vector<std::array<double, 3>> samples;
  for (int i = 0; i <= 600; ++i)
  {
    for (int j = 0; j < 1200; ++j)
    {
      const double theta = itk::Math::pi * i / 600.0;
      const double phi = 2.0 * itk::Math::pi * j / 1200.0;
      samples.push_back(
        { 18.0 * std::sin(theta) * std::cos(phi), 14.0 * std::sin(theta) * std::sin(phi), 28.0 * std::cos(theta) });
    }
  }
  for (const auto & q : { std::array<double, 3>{ 0, 0, 16 },
                          std::array<double, 3>{ 0, 5, 0 },
                          std::array<double, 3>{ 4, 0, 0 },
                          std::array<double, 3>{ 0, 3, -20 },
                          std::array<double, 3>{ 2, 0, 22 },
                          std::array<double, 3>{ 10, 8, 5 },
                          std::array<double, 3>{ 25, -3, 7 },
                          std::array<double, 3>{ 0, 0, 27.5 } })
  {
    double nearest = std::numeric_limits<double>::max();
    for (const auto & s : samples)
    {
      nearest = std::min(nearest, std::hypot(s[0] - q[0], s[1] - q[1], s[2] - q[2]));
    }
    const double d = ellipsoid.DistanceToSurface(at(q[0], q[1], q[2]));
    EXPECT_LE(d, nearest + 1e-9) << q[0] << " " << q[1] << " " << q[2];
    EXPECT_GE(d, nearest - 0.05) << q[0] << " " << q[1] << " " << q[2];
  }
}

TEST(SegmentationQuality, PlainGradientForcesDoNotReachThePoles)
{
  // The reason for the balloon and GVF: without them the poles stay behind.
  const SegmentationCase seed(VoxelGeometry(), 0.0);
  const auto             forces = seed.Forces(Capture::Balloon);
  auto                   filter = seed.MakeFilter(forces, Capture::Balloon, 500);
  filter->SetBalloon(0.0);
  filter->Update();
  const Result r = seed.Measure(filter);
  Report("plain gradient", r, 1.0);
  EXPECT_GT(r.maximumDistance, 5.0);
}

// Issue 15, item 3: the same parameters give the same surface from initial
// spheres of 258 to 65 538 vertices (root mean square edge 3.9 to 0.24
// voxel) when the internal forces are in physical units (ReferenceEdgeLength
// 0.5 voxel: about 2 sub-steps per iteration on the finest mesh). Known
// answer: the ellipsoid, reached within 0.2 voxel at every resolution, the
// mean distances within 0.05 voxel of each other, by each capture mechanism
// (with the balloon; without it, by gradient vector flow and by the region
// force). Measured: balloon 0.115 to 0.120 voxel, gradient vector flow 0.125
// to 0.126, region force 0.123 to 0.136.
TEST(SegmentationQuality, SameParametersGiveTheSameSurfaceFrom258To65538Vertices)
{
  const SegmentationCase seed(VoxelGeometry(), 0.0);
  for (const Capture capture : { Capture::Balloon, Capture::GradientVectorFlow, Capture::Region })
  {
    const auto   forces = seed.Forces(capture);
    double       smallest = std::numeric_limits<double>::max();
    double       largest = 0.0;
    const char * name = capture == Capture::Balloon              ? "balloon"
                        : capture == Capture::GradientVectorFlow ? "gradient vector flow"
                                                                 : "region force";
    for (unsigned int resolution = 3; resolution <= 7; ++resolution)
    {
      const Result r = seed.RunAtResolution(forces, capture, capture == Capture::Balloon ? 500 : 600, resolution, 0.5);
      const std::string label =
        std::string(name) + ", " + std::to_string((1u << (2 * resolution + 2)) + 2) + " vertices";
      Report(label.c_str(), r, 1.0);
      ExpectQuality(r, 1.0, 0.2, 0.6);
      smallest = std::min(smallest, r.meanDistance);
      largest = std::max(largest, r.meanDistance);
    }
    EXPECT_LE(largest - smallest, 0.05) << name;
  }
}

// Why: with the weights of the mesh's own edges, plain gradient forces (no
// balloon) bring the 258-vertex sphere onto the poles and leave the
// 1 026-vertex one 11 voxels short of them (issue 15's figures, 0.12 and 0.37
// voxel): the coarse mesh's rigidity is 256 times stronger in mm^4 (edges
// twice as long), and its bending pulls the caps out. In physical units
// neither reaches the poles: the same behaviour at both resolutions. (The
// mean distance of such a surface is not resolution independent: it counts
// the vertices the forces leave in the caps.)
TEST(SegmentationQuality, PlainGradientForcesBehaveAlikeAtAnyResolutionInPhysicalUnits)
{
  const SegmentationCase seed(VoxelGeometry(), 0.0);
  const auto             forces = seed.Forces(Capture::Balloon);
  const Result           coarse = seed.RunAtResolution(forces, Capture::Balloon, 500, 3, 0.0, false);
  const Result           fine = seed.RunAtResolution(forces, Capture::Balloon, 500, 4, 0.0, false);
  Report("plain gradient, mesh units, 258 vertices", coarse, 1.0);
  Report("plain gradient, mesh units, 1026 vertices", fine, 1.0);
  EXPECT_LT(coarse.maximumDistance, 0.6);
  EXPECT_GT(fine.maximumDistance, 5.0);
  EXPECT_GT(fine.meanDistance - coarse.meanDistance, 0.2);
  for (unsigned int resolution = 3; resolution <= 5; ++resolution)
  {
    const Result r = seed.RunAtResolution(forces, Capture::Balloon, 500, resolution, 0.5, false);
    Report(
      ("plain gradient, physical units, " + std::to_string((1u << (2 * resolution + 2)) + 2) + " vertices").c_str(),
      r,
      1.0);
    EXPECT_GT(r.maximumDistance, 5.0) << resolution;
  }
}

namespace
{
/** The seed's case under each capture mechanism, with noise, and on an
 * anisotropic rotated grid: tolerances in voxels (0: no bound on the largest
 * distance). */
struct QualityCase
{
  const char * name;
  bool         anisotropic;
  double       noise; // standard deviation, fraction of the contrast
  Capture      capture;
  unsigned int iterations;
  double       meanTolerance;
  double       maximumTolerance;
};

const QualityCase QualityCases[] = {
  { "balloon", false, 0.0, Capture::Balloon, 500, 0.2, 0.6 },
  { "gradient vector flow", false, 0.0, Capture::GradientVectorFlow, 600, 0.2, 0.6 },
  { "balloon, 25% noise", false, 0.25, Capture::Balloon, 500, 0.4, 0.0 },
  { "gradient vector flow, 25% noise", false, 0.25, Capture::GradientVectorFlow, 600, 0.4, 0.0 },
  { "balloon, anisotropic", true, 0.0, Capture::Balloon, 500, 0.2, 0.6 },
  { "gradient vector flow, anisotropic", true, 0.0, Capture::GradientVectorFlow, 600, 0.2, 0.6 },
};

class SegmentationQualityCases : public ::testing::TestWithParam<QualityCase>
{};
} // namespace

TEST_P(SegmentationQualityCases, ReachTheEllipsoid)
{
  const QualityCase &    c = GetParam();
  const SegmentationCase segmentation(c.anisotropic ? AnisotropicGeometry() : VoxelGeometry(), c.noise);
  const Result           r = segmentation.Run(c.capture, c.iterations);
  Report(c.name, r, segmentation.Voxel());
  ExpectQuality(r, segmentation.Voxel(), c.meanTolerance, c.maximumTolerance);
}

INSTANTIATE_TEST_SUITE_P(SeedCase, SegmentationQualityCases, ::testing::ValuesIn(QualityCases));

TEST(SegmentationQuality, ConvergenceStopsEarlyAtTheSameAccuracy)
{
  const SegmentationCase seed(VoxelGeometry(), 0.0);
  const Result           fixed = seed.Run(Capture::Balloon, 500, 0.0, true);
  ASSERT_EQ(fixed.meanDistanceHistory.size(), 500u);
  EXPECT_FALSE(fixed.converged) << "without a tolerance the schedule runs to its end";

  // Tolerance: a twentieth of a voxel per iteration, over the default window.
  const Result early = seed.Run(Capture::Balloon, 500, 0.05);
  Report("balloon with convergence tolerance 0.05 voxel", early, 1.0);
  EXPECT_TRUE(early.converged);
  EXPECT_LT(early.iterations, 500u);
  ExpectQuality(early, 1.0, 0.2, 0.6);

  // First iteration at which the fixed schedule is as accurate as the
  // converged run: mean within 0.005 voxel, max within 0.01 voxel.
  size_t needed = 0;
  while (needed < fixed.meanDistanceHistory.size() &&
         (fixed.meanDistanceHistory[needed] > early.meanDistance + 0.005 ||
          fixed.maximumDistanceHistory[needed] > early.maximumDistance + 0.01))
  {
    ++needed;
  }
  ++needed;
  std::cout << "fixed schedule reached that accuracy after " << needed << " iterations; converged run stopped after "
            << early.iterations << std::endl;
  EXPECT_LE(static_cast<double>(early.iterations), 1.2 * needed);
}

namespace
{
/** A zero force field around the origin, so only internal and balloon forces act. */
ForceImageType::Pointer
ZeroForceField()
{
  auto                     image = ForceImageType::New();
  ForceImageType::SizeType size;
  size.Fill(32);
  image->SetRegions(size);
  ForceImageType::PointType origin;
  origin.Fill(-15.5);
  image->SetOrigin(origin);
  image->Allocate();
  image->FillBuffer(ForceImageType::PixelType(0.0f));
  return image;
}

double
MeanRadius(const MeshType * mesh)
{
  double sum = 0.0;
  for (auto it = mesh->GetPoints()->Begin(); it != mesh->GetPoints()->End(); ++it)
  {
    sum += it.Value().EuclideanDistanceTo(PointType(0.0));
  }
  return sum / mesh->GetNumberOfPoints();
}

/** The same mesh with every triangle's orientation reversed. */
MeshType::Pointer
Reversed(const MeshType * mesh)
{
  auto reversed = MeshType::New();
  reversed->SetPoints(const_cast<MeshType::PointsContainer *>(mesh->GetPoints()));
  for (auto it = mesh->GetCells()->Begin(); it != mesh->GetCells()->End(); ++it)
  {
    MeshType::CellAutoPointer cell;
    it.Value()->MakeCopy(cell);
    const auto first = cell->PointIdsBegin()[1];
    cell->SetPointId(1, cell->PointIdsBegin()[2]);
    cell->SetPointId(2, first);
    reversed->SetCell(it.Index(), cell);
  }
  return reversed;
}
} // namespace

TEST(InternalForces, BalloonInflatesAlongTheOutwardNormalWhateverTheOrientation)
{
  PointType center;
  center.Fill(0.0);
  const auto sphere = itk::MakeSphereMesh<MeshType>(center, 8.0, 4);
  const auto inward = Reversed(sphere);
  const auto field = ZeroForceField();
  auto       run = [&](const MeshType * mesh, double balloon) {
    auto filter = FilterType::New();
    filter->SetInput(mesh);
    filter->SetForceImage(field);
    filter->SetBalloon(balloon);
    filter->SetNumberOfIterations(10);
    filter->Update();
    return std::make_pair(MeanRadius(filter->GetOutput()), filter->GetOrientationSign());
  };
  const double initial = MeanRadius(sphere);
  const auto   outwardResult = run(sphere, 0.1);
  const auto   inwardResult = run(inward, 0.1);
  EXPECT_NEAR(outwardResult.first - initial, 1.0, 0.01) << "10 iterations of 0.1 along the normal";
  EXPECT_EQ(outwardResult.second * inwardResult.second, -1.0) << "one of the two meshes is inward-oriented";
  EXPECT_DOUBLE_EQ(inwardResult.first, outwardResult.first);
  EXPECT_NEAR(run(sphere, -0.1).first - initial, -1.0, 0.01) << "a negative balloon deflates";
}

TEST(InternalForces, TangentialElasticityRegularisesWithoutShrinking)
{
  PointType center;
  center.Fill(0.0);
  const auto sphere = itk::MakeSphereMesh<MeshType>(center, 8.0, 4);
  const auto field = ZeroForceField();
  auto       run = [&](bool tangential, double rigidity) {
    auto filter = FilterType::New();
    filter->SetInput(sphere);
    filter->SetForceImage(field);
    filter->SetElasticity(0.5);
    filter->SetRigidity(rigidity);
    filter->SetTangentialElasticity(tangential);
    filter->SetNumberOfIterations(100);
    filter->Update();
    EXPECT_EQ(filter->GetInternalForceMagnitudes().size(), sphere->GetNumberOfPoints());
    return MeanRadius(filter->GetOutput());
  };
  const double initial = MeanRadius(sphere);
  EXPECT_NEAR(run(true, 0.0), initial, 0.01 * initial) << "tangential: the sphere keeps its size";
  EXPECT_LT(run(false, 0.0), 0.9 * initial) << "full Laplacian smoothing shrinks a sphere";
  // Rigidity (bending) leaves a sphere's constant curvature alone.
  EXPECT_NEAR(run(true, 0.25), initial, 0.01 * initial);
}

// Issue 15, item 3: with ReferenceEdgeLength L the full umbrella operator is
// the mean curvature flow dx/dt = a (L^2/4) Delta x, whatever the mesh's
// resolution: a sphere's radius follows R^2 = R0^2 - a L^2 t. Known answer:
// R0 = 8, a = 0.5, L = 1, 20 iterations: R = sqrt(54) = 7.348 from 258 to
// 65 538 vertices (1 to 42 sub-steps per iteration). With the weights of the
// mesh's own edges the same parameters shrink the coarse sphere by 2 mm and
// the fine one by 0.01 mm.
TEST(InternalForces, CurvatureFlowInPhysicalUnitsShrinksASphereAlikeAtAnyResolution)
{
  PointType center;
  center.Fill(0.0);
  const auto field = ZeroForceField();
  auto       run = [&](unsigned int resolution, double referenceEdgeLength, unsigned int * subSteps) {
    const auto sphere = itk::MakeSphereMesh<MeshType>(center, 8.0, resolution);
    auto       filter = FilterType::New();
    filter->SetInput(sphere);
    filter->SetForceImage(field);
    filter->SetElasticity(0.5);
    filter->TangentialElasticityOff();
    filter->SetReferenceEdgeLength(referenceEdgeLength);
    filter->SetNumberOfIterations(20);
    filter->Update();
    if (subSteps != nullptr)
    {
      *subSteps = filter->GetNumberOfSubSteps();
    }
    return MeanRadius(filter->GetOutput());
  };
  const double expected = std::sqrt(64.0 - 0.5 * 1.0 * 20.0);
  unsigned int subSteps = 0;
  for (unsigned int resolution = 3; resolution <= 7; ++resolution)
  {
    EXPECT_NEAR(run(resolution, 1.0, &subSteps), expected, 0.01) << resolution;
    EXPECT_EQ(subSteps > 1, resolution >= 5) << resolution;
  }
  EXPECT_LT(run(3, 0.0, nullptr), expected - 1.0) << "without a reference length";
  EXPECT_GT(run(7, 0.0, nullptr), 7.98) << "without a reference length";
}

TEST(InternalForces, DiagnosticsDescribeTheLastIteration)
{
  // Constant force (0.5, 0, 0) with ScaleFactor 2: every vertex moves by 1.
  using VectorForceImageType = itk::Image<itk::Vector<double, 3>, 3>;
  auto                           image = VectorForceImageType::New();
  VectorForceImageType::SizeType size;
  size.Fill(32);
  image->SetRegions(size);
  VectorForceImageType::PointType origin;
  origin.Fill(-15.5);
  image->SetOrigin(origin);
  image->Allocate();
  itk::Vector<double, 3> force;
  force.Fill(0.0);
  force[0] = 0.5;
  image->FillBuffer(force);
  PointType center;
  center.Fill(0.0);
  const auto sphere = itk::MakeSphereMesh<MeshType>(center, 5.0, 2);
  auto       filter = itk::DeformableMeshFilter<MeshType, VectorForceImageType>::New();
  filter->SetInput(sphere);
  filter->SetForceImage(image);
  filter->SetScaleFactor(2.0);
  filter->SetNumberOfIterations(3);
  filter->Update();
  ASSERT_EQ(filter->GetDisplacementMagnitudes().size(), sphere->GetNumberOfPoints());
  for (size_t i = 0; i < sphere->GetNumberOfPoints(); ++i)
  {
    EXPECT_FLOAT_EQ(filter->GetDisplacementMagnitudes()[i], 1.0f);
    EXPECT_FLOAT_EQ(filter->GetExternalForceMagnitudes()[i], 1.0f);
    EXPECT_FLOAT_EQ(filter->GetInternalForceMagnitudes()[i], 0.0f);
  }
  EXPECT_DOUBLE_EQ(filter->GetLastMaximumDisplacement(), 1.0);

  // MaximumStepLength bounds the displacement.
  filter->SetMaximumStepLength(0.25);
  filter->Update();
  EXPECT_NEAR(filter->GetOutput()->GetPoint(0)[0] - sphere->GetPoint(0)[0], 0.75, 1e-12);
  EXPECT_DOUBLE_EQ(filter->GetLastMaximumDisplacement(), 0.25);
}

namespace
{
/** One step of Elasticity a (not tangential), Rigidity b and Balloon c
 * without external force, computed here from the definitions: umbrella u_i =
 * mean of the edge neighbours minus x_i, rigidity term b (u_i - mean of the
 * neighbours' u), normal = sum over the vertex's triangles (polygons
 * fan-triangulated from their first point) of (y - x_i) x (z - x_i), made
 * unit and outward (the mesh is outward-oriented). */
std::vector<double>
ExpectedStep(const MeshType * mesh, double a, double b, double c)
{
  const size_t                       n = mesh->GetNumberOfPoints();
  std::vector<std::set<size_t>>      neighbours(n);
  std::vector<std::array<double, 3>> normals(n, { 0.0, 0.0, 0.0 });
  auto                               point = [mesh](size_t i) { return mesh->GetPoint(i); };
  for (auto it = mesh->GetCells()->Begin(); it != mesh->GetCells()->End(); ++it)
  {
    const auto * ids = it.Value()->PointIdsBegin();
    const auto   count = it.Value()->GetNumberOfPoints();
    const bool   closed = count >= 3;
    for (unsigned int k = 0; k + (closed ? 0 : 1) < count; ++k)
    {
      const size_t p = ids[k];
      const size_t q = ids[(k + 1) % count];
      neighbours[p].insert(q);
      neighbours[q].insert(p);
    }
    for (unsigned int k = 1; closed && k + 1 < count; ++k)
    {
      const size_t corner[3] = { ids[0], ids[k], ids[k + 1] };
      for (unsigned int m = 0; m < 3; ++m)
      {
        const auto x = point(corner[m]);
        const auto y = point(corner[(m + 1) % 3]) - x;
        const auto z = point(corner[(m + 2) % 3]) - x;
        normals[corner[m]][0] += y[1] * z[2] - y[2] * z[1];
        normals[corner[m]][1] += y[2] * z[0] - y[0] * z[2];
        normals[corner[m]][2] += y[0] * z[1] - y[1] * z[0];
      }
    }
  }
  std::vector<double> umbrella(3 * n, 0.0);
  for (size_t i = 0; i < n; ++i)
  {
    for (const size_t j : neighbours[i])
    {
      for (unsigned int d = 0; d < 3; ++d)
      {
        umbrella[3 * i + d] += (point(j)[d] - point(i)[d]) / neighbours[i].size();
      }
    }
  }
  std::vector<double> moved(3 * n);
  for (size_t i = 0; i < n; ++i)
  {
    const auto & m = normals[i];
    const double length = std::sqrt(m[0] * m[0] + m[1] * m[1] + m[2] * m[2]);
    for (unsigned int d = 0; d < 3; ++d)
    {
      double mean = 0.0;
      for (const size_t j : neighbours[i])
      {
        mean += umbrella[3 * j + d] / neighbours[i].size();
      }
      const double rigid = neighbours[i].empty() ? 0.0 : b * (umbrella[3 * i + d] - mean);
      moved[3 * i + d] = point(i)[d] + a * umbrella[3 * i + d] + rigid + (length > 0.0 ? c * m[d] / length : 0.0);
    }
  }
  return moved;
}

/** Vertices the filter could not store as a single fan, from its Print(). */
size_t
GeneralVertexCount(const FilterType * filter)
{
  std::ostringstream os;
  filter->Print(os);
  const std::string text = os.str();
  const std::string key = "vertices outside a single fan: ";
  const auto        where = text.find(key);
  return where == std::string::npos ? size_t(-1) : std::stoul(text.substr(where + key.size()));
}

/** Whether the filter processes the vertices of each chunk in the order of
 * their numbers of neighbours, read from its Print() output. */
bool
OrderedByValence(const FilterType * filter)
{
  std::ostringstream os;
  filter->Print(os);
  return os.str().find("OrderedByValence: On") != std::string::npos;
}
} // namespace

/** A mesh of the given points and cells: 2 ids a line, 3 a triangle, 4 a
 * quadrilateral. */
MeshType::Pointer
MakeMesh(const MeshType * points, const std::vector<std::vector<itk::IdentifierType>> & cells)
{
  auto mesh = MeshType::New();
  mesh->SetPoints(const_cast<MeshType::PointsContainer *>(points->GetPoints()));
  itk::IdentifierType id = 0;
  for (const auto & ids : cells)
  {
    MeshType::CellAutoPointer cell;
    if (ids.size() == 2)
    {
      cell.TakeOwnership(new itk::LineCell<MeshType::CellType>);
    }
    else if (ids.size() == 3)
    {
      cell.TakeOwnership(new itk::TriangleCell<MeshType::CellType>);
    }
    else
    {
      cell.TakeOwnership(new itk::QuadrilateralCell<MeshType::CellType>);
    }
    cell->SetPointIds(ids.data());
    mesh->SetCell(id++, cell);
  }
  return mesh;
}

namespace
{
/** One step of the filter on \a mesh (Elasticity 0.5, not tangential,
 * \a rigidity, Balloon 0.3); \a largestError: the largest coordinate
 * difference from ExpectedStep(). */
FilterType::Pointer
OneStep(const MeshType * mesh, const ForceImageType * field, double rigidity, double & largestError)
{
  auto filter = FilterType::New();
  filter->SetInput(mesh);
  filter->SetForceImage(field);
  filter->SetElasticity(0.5);
  filter->TangentialElasticityOff();
  filter->SetRigidity(rigidity);
  filter->SetBalloon(0.3);
  filter->SetNumberOfIterations(1);
  filter->Update();
  const auto expected = ExpectedStep(mesh, 0.5, rigidity, 0.3);
  largestError = 0.0;
  for (size_t i = 0; i < mesh->GetNumberOfPoints(); ++i)
  {
    for (unsigned int d = 0; d < 3; ++d)
    {
      largestError = std::max(largestError, std::abs(filter->GetOutput()->GetPoint(i)[d] - expected[3 * i + d]));
    }
  }
  return filter;
}
} // namespace

TEST(InternalForces, OneStepMatchesTheDefinitionsOnClosedOpenAndIrregularVertices)
{
  PointType center;
  center.Fill(0.0);
  const auto                                    sphere = itk::MakeSphereMesh<MeshType>(center, 8.0, 3);
  std::vector<std::vector<itk::IdentifierType>> triangles;
  for (auto it = sphere->GetCells()->Begin(); it != sphere->GetCells()->End(); ++it)
  {
    const auto * ids = it.Value()->PointIdsBegin();
    triangles.push_back({ ids[0], ids[1], ids[2] });
  }

  // Open: the triangles near the north pole removed, a hole with a boundary.
  std::vector<std::vector<itk::IdentifierType>> open;
  for (const auto & t : triangles)
  {
    if (sphere->GetPoint(t[0])[2] + sphere->GetPoint(t[1])[2] + sphere->GetPoint(t[2])[2] < 3.0 * 7.0)
    {
      open.push_back(t);
    }
  }
  ASSERT_LT(open.size(), triangles.size());

  // Irregular: triangles 0 and its neighbour across edge (a, c) merged into a
  // quadrilateral, triangle 100 repeated (a non-manifold fan) and a line
  // between two far points (an edge in no triangle).
  std::vector<std::vector<itk::IdentifierType>> irregular;
  const auto &                                  t0 = triangles[0];
  size_t                                        neighbour = 0;
  itk::IdentifierType                           fourth = 0;
  for (size_t k = 1; k < triangles.size() && neighbour == 0; ++k)
  {
    for (unsigned int m = 0; m < 3; ++m)
    {
      if (triangles[k][m] == t0[0] && triangles[k][(m + 1) % 3] == t0[2])
      {
        neighbour = k;
        fourth = triangles[k][(m + 2) % 3];
      }
    }
  }
  ASSERT_NE(neighbour, 0u);
  irregular.push_back({ t0[0], t0[1], t0[2], fourth });
  for (size_t k = 1; k < triangles.size(); ++k)
  {
    if (k != neighbour)
    {
      irregular.push_back(triangles[k]);
    }
  }
  irregular.push_back(triangles[100]);
  irregular.push_back({ triangles[200][0], triangles[5][1] });

  const auto                                            field = ZeroForceField();
  const std::vector<std::vector<itk::IdentifierType>> * cases[] = { &triangles, &open, &irregular };
  for (const auto * cellsOfCase : cases)
  {
    const auto & cells = *cellsOfCase;
    const auto   mesh = MakeMesh(sphere, cells);
    for (const double rigidity : { 0.0, 0.2 })
    {
      double     largestError = 0.0;
      const auto filter = OneStep(mesh, field, rigidity, largestError);
      ASSERT_EQ(filter->GetOrientationSign(), 1.0);
      // With rigidity the umbrella vectors and normals pass through single
      // precision between the two passes of the step: 6e-8 of forces < 1.
      EXPECT_LT(largestError, rigidity > 0.0 ? 1e-7 : 1e-12) << cells.size() << " cells, rigidity " << rigidity;
      // Every vertex of the closed and the open mesh lies in a single fan.
      EXPECT_EQ(GeneralVertexCount(filter) > 0, cellsOfCase == &irregular) << cells.size() << " cells";
    }
  }
}

TEST(InternalForces, OneStepMatchesTheDefinitionsWhateverTheValence)
{
  const auto field = ZeroForceField();
  const auto check = [&field](const MeshType * mesh, const std::string & name, bool ordered) {
    for (const double rigidity : { 0.0, 0.2 })
    {
      double     largestError = 0.0;
      const auto filter = OneStep(mesh, field, rigidity, largestError);
      ASSERT_EQ(filter->GetOrientationSign(), 1.0) << name;
      EXPECT_EQ(GeneralVertexCount(filter), 0u) << name;
      EXPECT_EQ(OrderedByValence(filter), ordered) << name;
      EXPECT_LT(largestError, rigidity > 0.0 ? 1e-6 : 1e-12) << name << ", rigidity " << rigidity;
    }
  };
  const auto addTriangle = [](MeshType * mesh, itk::IdentifierType id, const std::array<itk::IdentifierType, 3> & t) {
    MeshType::CellAutoPointer cell;
    cell.TakeOwnership(new itk::TriangleCell<MeshType::CellType>);
    for (unsigned int m = 0; m < 3; ++m)
    {
      cell->SetPointId(m, t[m]);
    }
    mesh->SetCell(id, cell);
  };

  // Irregular bipyramids: two apexes of valence K (a closed ring of K
  // neighbours) around a ring of K vertices of valence 4. K from 3 to 12
  // covers the valences with straight-line code and those without. The
  // filter orders the vertices by valence when no valence is shared by three
  // quarters of them: here for K = 3 and 5.
  for (unsigned int K = 3; K <= 12; ++K)
  {
    auto      mesh = MeshType::New();
    PointType p;
    p[0] = 0.3;
    p[1] = -0.2;
    p[2] = 6.0;
    mesh->SetPoint(0, p);
    p[0] = -0.4;
    p[1] = 0.1;
    p[2] = -5.0;
    mesh->SetPoint(1, p);
    for (unsigned int k = 0; k < K; ++k)
    {
      const double angle = 2.0 * itk::Math::pi * (k + 0.2 * std::sin(5.0 * k)) / K;
      const double radius = 5.0 + 0.7 * std::sin(3.0 * k);
      p[0] = radius * std::cos(angle);
      p[1] = radius * std::sin(angle);
      p[2] = 0.5 * std::cos(2.0 * k);
      mesh->SetPoint(2 + k, p);
    }
    for (unsigned int k = 0; k < K; ++k)
    {
      const itk::IdentifierType a = 2 + k;
      const itk::IdentifierType b = 2 + (k + 1) % K;
      addTriangle(mesh, 2 * k, { 0, a, b });
      addTriangle(mesh, 2 * k + 1, { 1, b, a });
    }
    check(mesh, "bipyramid K " + std::to_string(K), K == 3 || K == 5);
  }

  // An irregular icosahedron: every vertex of valence 5.
  const double phi = (1.0 + std::sqrt(5.0)) / 2.0;
  auto         icosahedron = MeshType::New();
  for (unsigned int k = 0; k < 12; ++k)
  {
    // (0, +-1, +-phi) and its cyclic permutations.
    const double a = (k & 1) ? -1.0 : 1.0;
    const double b = (k & 2) ? -phi : phi;
    const double v[3] = { 0.0, a, b };
    PointType    p;
    for (unsigned int d = 0; d < 3; ++d)
    {
      p[d] = 3.0 * v[(d + 3 - k / 4) % 3];
    }
    icosahedron->SetPoint(k, p);
  }
  // Faces: triples of vertices two apart (the edge length), oriented outward;
  // the vertices are moved off the regular shape afterwards.
  itk::IdentifierType faces = 0;
  const auto          near = [&icosahedron](itk::IdentifierType i, itk::IdentifierType j) {
    return icosahedron->GetPoint(i).EuclideanDistanceTo(icosahedron->GetPoint(j)) < 6.5;
  };
  for (itk::IdentifierType i = 0; i < 12; ++i)
  {
    for (itk::IdentifierType j = i + 1; j < 12; ++j)
    {
      for (itk::IdentifierType k = j + 1; k < 12; ++k)
      {
        if (near(i, j) && near(j, k) && near(i, k))
        {
          const auto a = icosahedron->GetPoint(i);
          const auto e = icosahedron->GetPoint(j) - a;
          const auto f = icosahedron->GetPoint(k) - a;
          const auto outward = itk::CrossProduct(e, f) * a.GetVectorFromOrigin() > 0.0;
          addTriangle(icosahedron,
                      faces++,
                      outward ? std::array<itk::IdentifierType, 3>{ i, j, k }
                              : std::array<itk::IdentifierType, 3>{ i, k, j });
        }
      }
    }
  }
  ASSERT_EQ(faces, 20u);
  for (itk::IdentifierType k = 0; k < 12; ++k)
  {
    PointType p = icosahedron->GetPoint(k);
    for (unsigned int d = 0; d < 3; ++d)
    {
      p[d] += 0.4 * std::sin(7.0 * k + 2.0 * d);
    }
    icosahedron->SetPoint(k, p);
  }
  check(icosahedron, "icosahedron", false);

  // A marching-cubes mesh of a ball: mixed valences over many chunks.
  using MaskType = itk::Image<unsigned char, 3>;
  auto               mask = MaskType::New();
  MaskType::SizeType maskSize;
  maskSize.Fill(24);
  mask->SetRegions(maskSize);
  mask->Allocate();
  for (itk::ImageRegionIteratorWithIndex<MaskType> it(mask, mask->GetBufferedRegion()); !it.IsAtEnd(); ++it)
  {
    const auto   index = it.GetIndex();
    const double x = index[0] - 11.3;
    const double y = index[1] - 12.1;
    const double z = index[2] - 11.7;
    it.Set(x * x / 64.0 + y * y / 36.0 + z * z / 49.0 < 1.0 ? 1 : 0);
  }
  auto marchingCubes = itk::BinaryMask3DMeshSource<MaskType, MeshType>::New();
  marchingCubes->SetInput(mask);
  marchingCubes->SetObjectValue(1);
  marchingCubes->Update();
  ASSERT_GT(marchingCubes->GetOutput()->GetNumberOfPoints(), 10 * itk::DeformableMeshFilterDetail::ChunkSize);
  check(marchingCubes->GetOutput(), "marching cubes", true);
}

TEST(InternalForces, DiagnosticsAreTheSameWhateverObservesTheFilter)
{
  PointType center;
  center.Fill(0.0);
  const auto sphere = itk::MakeSphereMesh<MeshType>(center, 8.0, 3);
  // A field pulling toward the origin, growing with the distance.
  auto field = ZeroForceField();
  for (itk::ImageRegionIteratorWithIndex<ForceImageType> it(field, field->GetBufferedRegion()); !it.IsAtEnd(); ++it)
  {
    ForceImageType::PointType p;
    field->TransformIndexToPhysicalPoint(it.GetIndex(), p);
    ForceImageType::PixelType f;
    for (unsigned int d = 0; d < 3; ++d)
    {
      f[d] = static_cast<float>(-0.05 * p[d]);
    }
    it.Set(f);
  }
  auto make = [&]() {
    auto filter = FilterType::New();
    filter->SetInput(sphere);
    filter->SetForceImage(field);
    filter->SetElasticity(0.3);
    filter->SetRigidity(0.1);
    filter->SetBalloon(0.05);
    return filter;
  };
  auto diagnostics = [](const FilterType * filter) {
    return std::vector<std::vector<float>>{ filter->GetDisplacementMagnitudes(),
                                            filter->GetExternalForceMagnitudes(),
                                            filter->GetInternalForceMagnitudes() };
  };

  auto plain = make();
  plain->SetNumberOfIterations(7);
  plain->Update();
  const auto expected = diagnostics(plain);
  ASSERT_EQ(expected[0].size(), sphere->GetNumberOfPoints());
  EXPECT_GT(*std::max_element(expected[1].begin(), expected[1].end()), 0.0f);
  EXPECT_GT(*std::max_element(expected[2].begin(), expected[2].end()), 0.0f);

  auto observed = make();
  observed->AddObserver(itk::IterationEvent(), [](const itk::EventObject &) {});
  observed->SetNumberOfIterations(7);
  observed->Update();
  EXPECT_EQ(diagnostics(observed), expected);

  auto resumed = make();
  resumed->SetIterateFromZero(false);
  resumed->SetNumberOfIterations(3);
  resumed->Update();
  resumed->SetNumberOfIterations(7);
  resumed->Update();
  EXPECT_EQ(diagnostics(resumed), expected);

  // Convergence ends the update early: the diagnostics are those of the
  // iteration it stopped at.
  auto converging = make();
  converging->SetConvergenceTolerance(10.0);
  converging->SetConvergenceWindow(2);
  converging->SetNumberOfIterations(7);
  converging->Update();
  ASSERT_TRUE(converging->GetConverged());
  auto reference = make();
  reference->SetNumberOfIterations(converging->GetCurrentIteration());
  reference->Update();
  EXPECT_EQ(diagnostics(converging), diagnostics(reference));
}

TEST(InternalForces, BalloonMovesAFlatDiskAlongItsNormalWhateverTheValence)
{
  // A flat disk in z = 2: a centre joined to 20 000 rim points (one fan of
  // 20 000 triangles around the centre, two triangles at each rim point).
  // The balloon alone moves every point by 0.1 along z, the same way.
  constexpr unsigned int rim = 20000;
  auto                   disk = MeshType::New();
  disk->SetPoint(0, PointType(std::array<double, 3>{ { 0.0, 0.0, 2.0 } }.data()));
  for (unsigned int k = 0; k < rim; ++k)
  {
    const double angle = 6.283185307179586 * k / rim;
    disk->SetPoint(k + 1,
                   PointType(std::array<double, 3>{ { 10.0 * std::cos(angle), 10.0 * std::sin(angle), 2.0 } }.data()));
  }
  std::vector<std::vector<itk::IdentifierType>> triangles;
  for (unsigned int k = 0; k < rim; ++k)
  {
    triangles.push_back({ 0, k + 1, (k + 1) % rim + 1 });
  }
  const auto mesh = MakeMesh(disk, triangles);
  auto       filter = FilterType::New();
  filter->SetInput(mesh);
  filter->SetForceImage(ZeroForceField());
  filter->SetBalloon(0.1);
  filter->SetNumberOfIterations(1);
  filter->Update();
  EXPECT_EQ(GeneralVertexCount(filter), 0u);
  const double direction = filter->GetOutput()->GetPoint(0)[2] - 2.0;
  EXPECT_NEAR(std::abs(direction), 0.1, 1e-12);
  for (itk::IdentifierType i = 0; i <= rim; ++i)
  {
    const auto moved = filter->GetOutput()->GetPoint(i) - mesh->GetPoint(i);
    ASSERT_NEAR(moved[0], 0.0, 1e-12) << "point " << i;
    ASSERT_NEAR(moved[1], 0.0, 1e-12) << "point " << i;
    ASSERT_NEAR(moved[2], direction, 1e-12) << "point " << i;
  }
}
