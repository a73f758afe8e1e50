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

// DeformableMeshFilter on 2-D contours (itk::Mesh<double, 2> of line and
// polygon cells over a 2-D force image), and the boundary of open contours
// and open surfaces (FixedBoundary). Known answers: distances to analytic
// curves (an ellipse, a rotated ellipse imaged with anisotropic pixels and a
// rotated direction, a five-pointed star), ends and rims that do not move,
// the iteration contract, and the exceptions of bad input.

#include "itkDeformableMeshFilter.h"
#include "itkExternalForceImageFilter.h"
#include "itkImageRegionIteratorWithIndex.h"
#include "itkLineCell.h"
#include "itkMesh.h"
#include "itkPolygonCell.h"
#include "itkTriangleCell.h"

#include "edmTestUtilities.h"

#include "gtest/gtest.h"

#include <array>
#include <cmath>
#include <functional>
#include <limits>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <vector>

namespace
{
using MeshType = itk::Mesh<double, 2, itk::DefaultStaticMeshTraits<double, 2, 2, double, double, double>>;
using PointType = MeshType::PointType;
using ImageType = itk::Image<float, 2>;
using ForceImageType = itk::Image<itk::CovariantVector<float, 2>, 2>;
using FilterType = itk::DeformableMeshFilter<MeshType, ForceImageType>;
using CellType = MeshType::CellType;
using LineType = itk::LineCell<CellType>;
using PolygonType = itk::PolygonCell<CellType>;

constexpr double pi = 3.14159265358979323846;

PointType
Point(double x, double y)
{
  PointType p;
  p[0] = x;
  p[1] = y;
  return p;
}

/** A closed curve r(t) (t in [0, 2 pi)), in physical space. */
using Curve = std::function<PointType(double)>;

/** The ellipse of centre c, semi-axes a and b, the a-axis at \a angle
 * radians from x. */
Curve
Ellipse(const PointType & c, double a, double b, double angle)
{
  return [=](double t) {
    const double u = a * std::cos(t);
    const double v = b * std::sin(t);
    return Point(c[0] + std::cos(angle) * u - std::sin(angle) * v, c[1] + std::sin(angle) * u + std::cos(angle) * v);
  };
}

/** A five-pointed star: radius r0 + amplitude cos(5 t) around c. */
Curve
Star(const PointType & c, double r0, double amplitude)
{
  return [=](double t) {
    const double r = r0 + amplitude * std::cos(5.0 * t);
    return Point(c[0] + r * std::cos(t), c[1] + r * std::sin(t));
  };
}

/** Mean and largest distance of the mesh's points to the curve, against
 * 200 000 samples of the curve refined by golden-section search around the
 * nearest one (exact to 1e-9 mm for these smooth curves). */
void
MeasureDistance(const MeshType * mesh, const Curve & curve, double & mean, double & maximum)
{
  constexpr unsigned int samples = 200000;
  std::vector<PointType> dense(samples);
  for (unsigned int k = 0; k < samples; ++k)
  {
    dense[k] = curve(2.0 * pi * k / samples);
  }
  mean = 0.0;
  maximum = 0.0;
  const auto n = mesh->GetNumberOfPoints();
  for (itk::IdentifierType i = 0; i < n; ++i)
  {
    const PointType p = mesh->GetPoint(i);
    unsigned int    best = 0;
    double          bestDistance = std::numeric_limits<double>::max();
    for (unsigned int k = 0; k < samples; ++k)
    {
      const double d = p.SquaredEuclideanDistanceTo(dense[k]);
      if (d < bestDistance)
      {
        bestDistance = d;
        best = k;
      }
    }
    double lo = 2.0 * pi * (best - 1.0) / samples;
    double hi = 2.0 * pi * (best + 1.0) / samples;
    for (unsigned int step = 0; step < 60; ++step)
    {
      const double m1 = lo + (hi - lo) * 0.381966;
      const double m2 = hi - (hi - lo) * 0.381966;
      if (p.SquaredEuclideanDistanceTo(curve(m1)) < p.SquaredEuclideanDistanceTo(curve(m2)))
      {
        hi = m2;
      }
      else
      {
        lo = m1;
      }
    }
    const double d = std::min(std::sqrt(bestDistance), p.EuclideanDistanceTo(curve(0.5 * (lo + hi))));
    mean += d;
    maximum = std::max(maximum, d);
  }
  mean /= static_cast<double>(n);
}

/** The image's geometry. */
struct Geometry
{
  ImageType::SizeType      size;
  ImageType::SpacingType   spacing;
  ImageType::PointType     origin;
  ImageType::DirectionType direction;
};

Geometry
UnitGeometry(unsigned int size)
{
  Geometry g;
  g.size.Fill(size);
  g.spacing.Fill(1.0);
  g.origin.Fill(0.0);
  g.direction.SetIdentity();
  return g;
}

/** Anti-aliased image of the region inside a closed star-shaped curve
 * around \a center: each pixel holds 100 times the fraction of its 16 x 16
 * sub-samples inside (the curve's radius at the sub-sample's angle). */
ImageType::Pointer
MakeImage(const Geometry & g, const PointType & center, const std::function<bool(const PointType &)> & inside)
{
  auto image = ImageType::New();
  image->SetRegions(g.size);
  image->SetSpacing(g.spacing);
  image->SetOrigin(g.origin);
  image->SetDirection(g.direction);
  image->Allocate();
  (void)center;
  constexpr unsigned int sub = 16;
  for (itk::ImageRegionIteratorWithIndex<ImageType> it(image, image->GetBufferedRegion()); !it.IsAtEnd(); ++it)
  {
    unsigned int count = 0;
    for (unsigned int a = 0; a < sub; ++a)
    {
      for (unsigned int b = 0; b < sub; ++b)
      {
        itk::ContinuousIndex<double, 2> index;
        index[0] = it.GetIndex()[0] - 0.5 + (a + 0.5) / sub;
        index[1] = it.GetIndex()[1] - 0.5 + (b + 0.5) / sub;
        PointType p;
        image->TransformContinuousIndexToPhysicalPoint(index, p);
        count += inside(p) ? 1 : 0;
      }
    }
    it.Set(100.0f * static_cast<float>(count) / (sub * sub));
  }
  return image;
}

std::function<bool(const PointType &)>
InsideEllipse(const PointType & c, double a, double b, double angle)
{
  return [=](const PointType & p) {
    const double dx = p[0] - c[0];
    const double dy = p[1] - c[1];
    const double u = std::cos(angle) * dx + std::sin(angle) * dy;
    const double v = -std::sin(angle) * dx + std::cos(angle) * dy;
    return (u / a) * (u / a) + (v / b) * (v / b) <= 1.0;
  };
}

std::function<bool(const PointType &)>
InsideStar(const PointType & c, double r0, double amplitude)
{
  return [=](const PointType & p) {
    const double dx = p[0] - c[0];
    const double dy = p[1] - c[1];
    return std::hypot(dx, dy) <= r0 + amplitude * std::cos(5.0 * std::atan2(dy, dx));
  };
}

ForceImageType::Pointer
Forces(const ImageType * image, double sigma, bool gvf)
{
  auto forces = itk::ExternalForceImageFilter<ImageType, ForceImageType>::New();
  forces->SetInput(image);
  forces->SetSigma(sigma);
  forces->SetUseGradientVectorFlow(gvf);
  forces->Update();
  ForceImageType::Pointer field = forces->GetOutput();
  field->DisconnectPipeline();
  return field;
}

/** A circle of \a n points around \a c: one polygon cell (a closed
 * contour), or \a n line cells; counter-clockwise unless \a clockwise. */
MeshType::Pointer
MakeCircle(const PointType & c, double radius, unsigned int n, bool polygon = true, bool clockwise = false)
{
  auto mesh = MeshType::New();
  for (unsigned int k = 0; k < n; ++k)
  {
    const double t = (clockwise ? -2.0 : 2.0) * pi * k / n;
    mesh->SetPoint(k, Point(c[0] + radius * std::cos(t), c[1] + radius * std::sin(t)));
  }
  if (polygon)
  {
    CellType::CellAutoPointer cell;
    cell.TakeOwnership(new PolygonType);
    for (unsigned int k = 0; k < n; ++k)
    {
      cell->SetPointId(k, k);
    }
    mesh->SetCell(0, cell);
  }
  else
  {
    for (unsigned int k = 0; k < n; ++k)
    {
      CellType::CellAutoPointer cell;
      cell.TakeOwnership(new LineType);
      cell->SetPointId(0, k);
      cell->SetPointId(1, (k + 1) % n);
      mesh->SetCell(k, cell);
    }
  }
  return mesh;
}

/** An open contour: \a n points from \a a to \a b along a straight line,
 * bowed sideways by \a bow at the middle (a parabola), as line cells. */
MeshType::Pointer
MakeOpenContour(const PointType & a, const PointType & b, unsigned int n, double bow)
{
  auto         mesh = MeshType::New();
  const double dx = b[0] - a[0];
  const double dy = b[1] - a[1];
  const double length = std::hypot(dx, dy);
  for (unsigned int k = 0; k < n; ++k)
  {
    const double s = static_cast<double>(k) / (n - 1);
    const double side = bow * 4.0 * s * (1.0 - s);
    mesh->SetPoint(k, Point(a[0] + s * dx - side * dy / length, a[1] + s * dy + side * dx / length));
  }
  for (unsigned int k = 0; k + 1 < n; ++k)
  {
    CellType::CellAutoPointer cell;
    cell.TakeOwnership(new LineType);
    cell->SetPointId(0, k);
    cell->SetPointId(1, k + 1);
    mesh->SetCell(k, cell);
  }
  return mesh;
}

std::string
ErrorOf(FilterType * filter)
{
  return edm::test::UpdateAndGetError(filter);
}
} // namespace

// The measure: a point at a known distance from the ellipse (on an axis, and
// the centre, whose nearest points are the ends of the minor axis).
TEST(DeformableContour, DistanceToAnAnalyticCurveKnownAnswers)
{
  const Curve ellipse = Ellipse(Point(0.0, 0.0), 20.0, 14.0, 0.0);
  auto        mesh = MeshType::New();
  mesh->SetPoint(0, Point(23.0, 0.0));
  mesh->SetPoint(1, Point(0.0, 10.0));
  mesh->SetPoint(2, Point(0.0, 0.0));
  double mean = 0.0;
  double maximum = 0.0;
  MeasureDistance(mesh, ellipse, mean, maximum);
  EXPECT_NEAR(maximum, 14.0, 1e-9);
  EXPECT_NEAR(mean, (3.0 + 4.0 + 14.0) / 3.0, 1e-9);
}

// A circle of 200 points pulled onto the edge of an ellipse of semi-axes
// (20, 14) pixels by the gradient forces of its anti-aliased image (sigma 1
// pixel; the circle is at most 3 pixels from the edge): within 0.1 pixel on
// average, 0.3 at most, of the true curve. The same from a clockwise circle
// of line cells (the orientation is normalised).
TEST(DeformableContour, CircleReachesAnEllipse)
{
  const Geometry  g = UnitGeometry(72);
  const PointType center = Point(35.3, 36.1);
  const auto      image = MakeImage(g, center, InsideEllipse(center, 20.0, 14.0, 0.0));
  const auto      forces = Forces(image, 1.0, false);
  for (const bool polygon : { true, false })
  {
    auto filter = FilterType::New();
    filter->SetInput(MakeCircle(center, 17.0, 200, polygon, !polygon));
    filter->SetForceImage(forces);
    filter->SetScaleFactor(0.5);
    filter->SetElasticity(0.3);
    filter->SetNumberOfIterations(400);
    filter->Update();
    EXPECT_EQ(filter->GetNumberOfClosedContours(), 1u);
    EXPECT_EQ(filter->GetNumberOfOpenContours(), 0u);
    double mean = 0.0;
    double maximum = 0.0;
    MeasureDistance(filter->GetOutput(), Ellipse(center, 20.0, 14.0, 0.0), mean, maximum);
    std::cout << (polygon ? "polygon cell" : "line cells, clockwise") << ": mean " << mean << " pixel, max " << maximum
              << " pixel" << std::endl;
    EXPECT_LE(mean, 0.1);
    EXPECT_LE(maximum, 0.3);
  }
}

// SuppressTangentialDrift on a contour: the normal is the contour's, and the
// contour reaches the ellipse as closely as with the whole force.
TEST(DeformableContour, SuppressTangentialDriftReachesTheEllipseAsClosely)
{
  const Geometry  g = UnitGeometry(72);
  const PointType center = Point(35.3, 36.1);
  const auto      image = MakeImage(g, center, InsideEllipse(center, 20.0, 14.0, 0.0));
  const auto      forces = Forces(image, 1.0, false);
  double          means[2] = { 0.0, 0.0 };
  for (const bool suppress : { false, true })
  {
    auto filter = FilterType::New();
    filter->SetInput(MakeCircle(center, 17.0, 200));
    filter->SetForceImage(forces);
    filter->SetScaleFactor(0.5);
    filter->SetElasticity(0.3);
    filter->SetSuppressTangentialDrift(suppress);
    filter->SetNumberOfIterations(400);
    filter->Update();
    double maximum = 0.0;
    MeasureDistance(filter->GetOutput(), Ellipse(center, 20.0, 14.0, 0.0), means[suppress], maximum);
    std::cout << (suppress ? "suppressed" : "whole force") << ": mean " << means[suppress] << " pixel, max " << maximum
              << " pixel" << std::endl;
    EXPECT_LE(means[suppress], 0.1);
    EXPECT_LE(maximum, 0.3);
  }
  EXPECT_NEAR(means[1], means[0], 0.02);
}

// The same physical ellipse, rotated by 0.3 rad, imaged with pixels of
// 0.6 x 1.0 mm, a direction rotated by 0.5 rad and an origin away from 0:
// the tolerances in units of the smallest spacing (0.6 mm).
TEST(DeformableContour, CircleReachesARotatedEllipseInPhysicalUnits)
{
  Geometry g;
  g.size[0] = 110;
  g.size[1] = 70;
  g.spacing[0] = 0.6;
  g.spacing[1] = 1.0;
  g.origin[0] = 10.0;
  g.origin[1] = -25.0;
  g.direction(0, 0) = std::cos(0.5);
  g.direction(0, 1) = -std::sin(0.5);
  g.direction(1, 0) = std::sin(0.5);
  g.direction(1, 1) = std::cos(0.5);
  auto                            reference = ImageType::New();
  itk::ContinuousIndex<double, 2> middle;
  middle[0] = 54.3;
  middle[1] = 34.6;
  reference->SetSpacing(g.spacing);
  reference->SetOrigin(g.origin);
  reference->SetDirection(g.direction);
  PointType center;
  reference->TransformContinuousIndexToPhysicalPoint(middle, center);
  const double voxel = 0.6;
  const auto   image = MakeImage(g, center, InsideEllipse(center, 20.0, 14.0, 0.3));
  const auto   forces = Forces(image, 1.0, false);
  auto         filter = FilterType::New();
  filter->SetInput(MakeCircle(center, 17.0, 200));
  filter->SetForceImage(forces);
  filter->SetScaleFactor(0.5);
  filter->SetElasticity(0.3);
  filter->SetNumberOfIterations(400);
  filter->Update();
  double mean = 0.0;
  double maximum = 0.0;
  MeasureDistance(filter->GetOutput(), Ellipse(center, 20.0, 14.0, 0.3), mean, maximum);
  std::cout << "rotated, anisotropic: mean " << mean / voxel << " pixel, max " << maximum / voxel << " pixel"
            << std::endl;
  EXPECT_LE(mean, 0.1 * voxel);
  EXPECT_LE(maximum, 0.3 * voxel);
}

namespace
{
/** A 2-D force field of zeros over [0, size) pixels. */
ForceImageType::Pointer
ZeroForces(unsigned int size)
{
  auto                     field = ForceImageType::New();
  ForceImageType::SizeType s;
  s.Fill(size);
  field->SetRegions(s);
  field->Allocate();
  ForceImageType::PixelType zero;
  zero.Fill(0.0f);
  field->FillBuffer(zero);
  return field;
}

/** Two meshes have the same points, bit for bit. */
void
ExpectSamePoints(const MeshType * a, const MeshType * b)
{
  ASSERT_EQ(a->GetNumberOfPoints(), b->GetNumberOfPoints());
  for (itk::IdentifierType i = 0; i < a->GetNumberOfPoints(); ++i)
  {
    ASSERT_EQ(a->GetPoint(i)[0], b->GetPoint(i)[0]) << "point " << i;
    ASSERT_EQ(a->GetPoint(i)[1], b->GetPoint(i)[1]) << "point " << i;
  }
}

/** The ellipse case of CircleReachesAnEllipse, for the tests that need a
 * moving contour. */
struct EllipseCase
{
  PointType               center = Point(35.3, 36.1);
  ImageType::Pointer      image;
  ForceImageType::Pointer forces;

  EllipseCase()
  {
    image = MakeImage(UnitGeometry(72), center, InsideEllipse(center, 20.0, 14.0, 0.0));
    forces = Forces(image, 1.0, false);
  }

  FilterType::Pointer
  MakeFilter(const MeshType * mesh, unsigned long iterations) const
  {
    auto filter = FilterType::New();
    filter->SetInput(mesh);
    filter->SetForceImage(forces);
    filter->SetScaleFactor(0.5);
    filter->SetElasticity(0.3);
    filter->SetRigidity(0.05);
    filter->SetNumberOfIterations(iterations);
    return filter;
  }
};
} // namespace

// Outward is away from the region a closed contour encloses, whatever the
// order of its points: the balloon alone moves every point of a circle of
// radius 10 to radius 10.1 (the normal of a regular polygon's vertex is
// radial), from a counter-clockwise polygon cell and from clockwise line cells.
TEST(DeformableContour, BalloonInflatesAClosedContourWhateverItsOrientation)
{
  const PointType center = Point(20.0, 20.0);
  for (const bool clockwise : { false, true })
  {
    auto filter = FilterType::New();
    filter->SetInput(MakeCircle(center, 10.0, 64, !clockwise, clockwise));
    filter->SetForceImage(ZeroForces(40));
    filter->SetBalloon(0.1);
    filter->SetNumberOfIterations(1);
    filter->Update();
    EXPECT_EQ(filter->GetOrientationSign(), 1.0);
    for (itk::IdentifierType i = 0; i < 64; ++i)
    {
      EXPECT_NEAR(filter->GetOutput()->GetPoint(i).EuclideanDistanceTo(center), 10.1, 1e-12)
        << (clockwise ? "clockwise" : "counter-clockwise") << " point " << i;
    }
    // Diagnostics sized to the contour: the balloon's step everywhere.
    ASSERT_EQ(filter->GetDisplacementMagnitudes().size(), 64u);
    EXPECT_NEAR(filter->GetDisplacementMagnitudes()[7], 0.1, 1e-6);
  }
}

// Internal forces in physical units on a contour: with ReferenceEdgeLength L
// the membrane force (tangential part off) moves each point of a circle of
// radius R by a L^2 / (2 R) toward the centre per iteration (on a contour
// the umbrella vector is about (h^2 / 2) times the curvature vector, and the
// edge weight is L^2 / h^2), whatever the number of points: 64, 256 or 1024
// points on a circle of radius 10, a = 0.5, L = 1: 0.025 mm per iteration,
// in one sub-step or in 9 and 133.
TEST(DeformableContour, CurvatureFlowInPhysicalUnitsAtAnyResolution)
{
  const PointType center = Point(20.0, 20.0);
  for (const unsigned int n : { 64u, 256u, 1024u })
  {
    auto filter = FilterType::New();
    filter->SetInput(MakeCircle(center, 10.0, n));
    filter->SetForceImage(ZeroForces(40));
    filter->SetElasticity(0.5);
    filter->SetTangentialElasticity(false);
    filter->SetReferenceEdgeLength(1.0);
    filter->SetNumberOfIterations(1);
    filter->Update();
    double largest = 0.0;
    for (itk::IdentifierType i = 0; i < n; ++i)
    {
      largest = std::max(largest, std::abs(filter->GetOutput()->GetPoint(i).EuclideanDistanceTo(center) - 9.975));
    }
    std::cout << n << " points, " << filter->GetNumberOfSubSteps() << " sub-step(s): radius within " << largest
              << " mm of 9.975" << std::endl;
    EXPECT_LE(largest, 1e-4) << n << " points";
  }
}

// Several contours in one mesh: two circles, one a polygon cell and one
// clockwise line cells, each pulled onto its own ellipse of one image.
TEST(DeformableContour, SeveralContoursInOneMesh)
{
  const PointType left = Point(25.2, 30.4);
  const PointType right = Point(68.7, 31.9);
  const auto      insideLeft = InsideEllipse(left, 16.0, 12.0, 0.0);
  const auto      insideRight = InsideEllipse(right, 12.0, 16.0, 0.0);
  const auto      image =
    MakeImage(UnitGeometry(96), left, [&](const PointType & p) { return insideLeft(p) || insideRight(p); });
  const auto a = MakeCircle(left, 14.0, 160);
  const auto b = MakeCircle(right, 14.0, 160, false, true);
  auto       mesh = MeshType::New();
  for (itk::IdentifierType i = 0; i < 160; ++i)
  {
    mesh->SetPoint(i, a->GetPoint(i));
    mesh->SetPoint(160 + i, b->GetPoint(i));
  }
  CellType::CellAutoPointer polygon;
  polygon.TakeOwnership(new PolygonType);
  for (unsigned int k = 0; k < 160; ++k)
  {
    polygon->SetPointId(k, k);
  }
  mesh->SetCell(0, polygon);
  for (unsigned int k = 0; k < 160; ++k)
  {
    CellType::CellAutoPointer line;
    line.TakeOwnership(new LineType);
    line->SetPointId(0, 160 + (k + 1) % 160);
    line->SetPointId(1, 160 + k);
    mesh->SetCell(1 + k, line);
  }
  auto filter = FilterType::New();
  filter->SetInput(mesh);
  filter->SetForceImage(Forces(image, 1.0, false));
  filter->SetScaleFactor(0.5);
  filter->SetElasticity(0.3);
  filter->SetNumberOfIterations(400);
  filter->Update();
  EXPECT_EQ(filter->GetNumberOfClosedContours(), 2u);
  EXPECT_EQ(filter->GetNumberOfOpenContours(), 0u);
  EXPECT_EQ(filter->GetNumberOfBoundaryVertices(), 0u);
  auto first = MeshType::New();
  auto second = MeshType::New();
  for (itk::IdentifierType i = 0; i < 160; ++i)
  {
    first->SetPoint(i, filter->GetOutput()->GetPoint(i));
    second->SetPoint(i, filter->GetOutput()->GetPoint(160 + i));
  }
  double mean = 0.0;
  double maximum = 0.0;
  MeasureDistance(first, Ellipse(left, 16.0, 12.0, 0.0), mean, maximum);
  std::cout << "left: mean " << mean << " pixel, max " << maximum << std::endl;
  EXPECT_LE(mean, 0.1);
  EXPECT_LE(maximum, 0.3);
  MeasureDistance(second, Ellipse(right, 12.0, 16.0, 0.0), mean, maximum);
  std::cout << "right: mean " << mean << " pixel, max " << maximum << std::endl;
  EXPECT_LE(mean, 0.1);
  EXPECT_LE(maximum, 0.3);
}

// A concave shape: a five-pointed star (radius 18 +- 5 pixels: valleys at
// 13, tips at 23) reached from a circle of radius 8 inside it by the region
// force (the object's intensities estimated inside the circle), no balloon.
TEST(DeformableContour, RegionForceReachesAStar)
{
  const Geometry  g = UnitGeometry(64);
  const PointType center = Point(31.6, 32.2);
  const auto      image = MakeImage(g, center, InsideStar(center, 18.0, 5.0));
  auto            filter = FilterType::New();
  filter->SetInput(MakeCircle(center, 8.0, 240));
  filter->SetForceImage(Forces(image, 1.0, false));
  filter->SetIntensityImage(image);
  filter->SetRegionWeight(0.25);
  filter->SetScaleFactor(0.5);
  filter->SetElasticity(0.3);
  filter->SetNumberOfIterations(600);
  filter->Update();
  double mean = 0.0;
  double maximum = 0.0;
  MeasureDistance(filter->GetOutput(), Star(center, 18.0, 5.0), mean, maximum);
  std::cout << "star, region force: mean " << mean << " pixel, max " << maximum << " pixel" << std::endl;
  EXPECT_LE(mean, 0.15);
  EXPECT_LE(maximum, 0.5);
  // Without the region force the circle, 5 pixels from the nearest edge,
  // stays far from the star: the region force did the work.
  filter->SetRegionWeight(0.0);
  filter->Update();
  MeasureDistance(filter->GetOutput(), Star(center, 18.0, 5.0), mean, maximum);
  std::cout << "star, gradient forces alone: mean " << mean << " pixel" << std::endl;
  EXPECT_GE(mean, 2.0);
}

// The edge search in 2-D: with the region force and the edge search along
// the contour's normals, a circle of radius 8 inside the ellipse of semi-axes
// (20, 14) settles on its edge within 0.1 pixel on average, 0.3 at most, every
// point finding the edge. (The object of this noise-free image has no
// intensity spread: the edge search's minimum contrast, 1 % of the image's
// range, keeps the ripples of the smoothing inside it from being edges.)
TEST(DeformableContour, EdgeSearchFindsTheEllipsesEdge)
{
  const EllipseCase c;
  auto              filter = FilterType::New();
  filter->SetInput(MakeCircle(c.center, 8.0, 240));
  filter->SetForceImage(c.forces);
  filter->SetIntensityImage(c.image);
  filter->SetRegionWeight(0.25);
  filter->SetEdgeSearchWeight(0.25);
  filter->SetScaleFactor(0.5);
  filter->SetElasticity(0.3);
  filter->SetNumberOfIterations(400);
  filter->Update();
  double mean = 0.0;
  double maximum = 0.0;
  MeasureDistance(filter->GetOutput(), Ellipse(c.center, 20.0, 14.0, 0.0), mean, maximum);
  std::cout << "ellipse, region force and edge search: mean " << mean << " pixel, max " << maximum << " pixel, "
            << filter->GetNumberOfEdgeHits() << " edge hits of 240" << std::endl;
  EXPECT_LE(mean, 0.1);
  EXPECT_LE(maximum, 0.3);
  EXPECT_EQ(filter->GetNumberOfEdgeHits(), 240u);
}

// An open contour across the lower part of the ellipse, its middle pulled
// onto the edge: with FixedBoundary its two ends keep their input position
// bit for bit; with free ends (the default) they move.
TEST(DeformableContour, OpenContourWithFixedOrFreeEnds)
{
  const EllipseCase c;
  const auto        open = MakeOpenContour(
    Point(c.center[0] - 12.0, c.center[1] - 9.0), Point(c.center[0] + 12.0, c.center[1] - 9.0), 41, -3.0);
  for (const bool fixed : { true, false })
  {
    auto filter = c.MakeFilter(open, 300);
    filter->SetFixedBoundary(fixed);
    filter->Update();
    EXPECT_EQ(filter->GetNumberOfOpenContours(), 1u);
    EXPECT_EQ(filter->GetNumberOfClosedContours(), 0u);
    EXPECT_EQ(filter->GetNumberOfBoundaryVertices(), 2u);
    const MeshType * out = filter->GetOutput();
    // The middle reaches the ellipse's edge (2 pixels below it at the start).
    auto middle = MeshType::New();
    middle->SetPoint(0, out->GetPoint(20));
    double mean = 0.0;
    double maximum = 0.0;
    MeasureDistance(middle, Ellipse(c.center, 20.0, 14.0, 0.0), mean, maximum);
    EXPECT_LE(maximum, 0.3) << (fixed ? "fixed" : "free");
    for (const itk::IdentifierType end : { itk::IdentifierType{ 0 }, itk::IdentifierType{ 40 } })
    {
      if (fixed)
      {
        EXPECT_EQ(out->GetPoint(end)[0], open->GetPoint(end)[0]);
        EXPECT_EQ(out->GetPoint(end)[1], open->GetPoint(end)[1]);
        EXPECT_EQ(filter->GetDisplacementMagnitudes()[end], 0.0f);
      }
      else
      {
        EXPECT_GE(out->GetPoint(end).EuclideanDistanceTo(open->GetPoint(end)), 1.0) << "end " << end;
      }
    }
  }
}

namespace
{
/** A cell of the line type with more than 2 points (a polyline), as ITK 5.2
 * has none: the VTK bridge makes such cells. */
class TestPolyLineCell : public PolygonType
{
public:
  itk::CommonEnums::CellGeometry
  GetType() const override
  {
    return itk::CommonEnums::CellGeometry::LINE_CELL;
  }
};
} // namespace

// One line cell of n points is the chain of its n - 1 segments: the open
// contour of OpenContourWithFixedOrFreeEnds as one such cell gives the
// contour of its 40 line cells, its two ends fixed.
TEST(DeformableContour, LineCellOfSeveralPointsIsAChain)
{
  const EllipseCase c;
  const auto        segments = MakeOpenContour(
    Point(c.center[0] - 12.0, c.center[1] - 9.0), Point(c.center[0] + 12.0, c.center[1] - 9.0), 41, -3.0);
  auto chain = MeshType::New();
  chain->SetPoints(segments->GetPoints());
  CellType::CellAutoPointer cell;
  cell.TakeOwnership(new TestPolyLineCell);
  for (unsigned int k = 0; k < 41; ++k)
  {
    cell->SetPointId(k, k);
  }
  chain->SetCell(0, cell);
  MeshType::Pointer outputs[2];
  const MeshType *  inputs[2] = { segments, chain };
  for (unsigned int i = 0; i < 2; ++i)
  {
    auto filter = c.MakeFilter(inputs[i], 300);
    filter->SetFixedBoundary(true);
    filter->Update();
    EXPECT_EQ(filter->GetNumberOfOpenContours(), 1u);
    EXPECT_EQ(filter->GetNumberOfBoundaryVertices(), 2u);
    outputs[i] = filter->GetOutput();
    outputs[i]->DisconnectPipeline();
  }
  for (itk::IdentifierType k = 0; k < 41; ++k)
  {
    EXPECT_NEAR(outputs[1]->GetPoint(k)[0], outputs[0]->GetPoint(k)[0], 1e-9) << k;
    EXPECT_NEAR(outputs[1]->GetPoint(k)[1], outputs[0]->GetPoint(k)[1], 1e-9) << k;
  }
  EXPECT_EQ(outputs[1]->GetPoint(40)[0], segments->GetPoint(40)[0]);
}

// The step bound and convergence on contours: a balloon of 1 mm bounded by
// MaximumStepLength 0.25 moves a circle's points by 0.25 exactly; the
// ellipse case with ConvergenceTolerance 0.002 pixel stops before its 1000
// iterations with the accuracy of CircleReachesAnEllipse.
TEST(DeformableContour, StepBoundAndConvergence)
{
  const PointType center = Point(20.0, 20.0);
  auto            bounded = FilterType::New();
  bounded->SetInput(MakeCircle(center, 10.0, 64));
  bounded->SetForceImage(ZeroForces(40));
  bounded->SetBalloon(1.0);
  bounded->SetMaximumStepLength(0.25);
  bounded->SetNumberOfIterations(1);
  bounded->Update();
  for (itk::IdentifierType i = 0; i < 64; ++i)
  {
    EXPECT_NEAR(bounded->GetOutput()->GetPoint(i).EuclideanDistanceTo(center), 10.25, 1e-12) << "point " << i;
  }
  EXPECT_NEAR(bounded->GetLastMaximumDisplacement(), 0.25, 1e-12);

  const EllipseCase c;
  auto              filter = c.MakeFilter(MakeCircle(c.center, 17.0, 200), 1000);
  filter->SetRigidity(0.0);
  filter->SetConvergenceTolerance(0.002);
  filter->Update();
  EXPECT_TRUE(filter->GetConverged());
  EXPECT_LT(filter->GetCurrentIteration(), 1000u);
  double mean = 0.0;
  double maximum = 0.0;
  MeasureDistance(filter->GetOutput(), Ellipse(c.center, 20.0, 14.0, 0.0), mean, maximum);
  std::cout << "converged after " << filter->GetCurrentIteration() << " iterations: mean " << mean << " pixel, max "
            << maximum << " pixel" << std::endl;
  EXPECT_LE(mean, 0.1);
  EXPECT_LE(maximum, 0.3);
}

// Convergence along the normals: 120 points on the edge of a disc of radius
// 14 pixels, spaced unevenly (0.4 to 1.6 times their mean spacing), the
// tangential elasticity on. The shape is settled from the start; only the
// points slide along it toward even spacing. Measured on the whole
// displacement the filter runs while they slide; along the normals it stops
// within a few tens of iterations although they are still sliding by more
// than the tolerance, and both contours lie on the circle.
TEST(DeformableContour, ConvergenceAlongNormalsIgnoresPointsSlidingAlongTheContour)
{
  const PointType        center = Point(24.3, 23.8);
  const auto             image = MakeImage(UnitGeometry(48), center, InsideEllipse(center, 14.0, 14.0, 0.0));
  const auto             forces = Forces(image, 1.0, false);
  constexpr unsigned int n = 120;
  auto                   uneven = MeshType::New();
  for (unsigned int k = 0; k < n; ++k)
  {
    const double u = 2.0 * pi * k / n;
    const double t = u + 0.6 * std::sin(u);
    uneven->SetPoint(k, Point(center[0] + 14.0 * std::cos(t), center[1] + 14.0 * std::sin(t)));
  }
  CellType::CellAutoPointer cell;
  cell.TakeOwnership(new PolygonType);
  for (unsigned int k = 0; k < n; ++k)
  {
    cell->SetPointId(k, k);
  }
  uneven->SetCell(0, cell);

  constexpr double   tolerance = 0.002;
  itk::SizeValueType iterations[2] = { 0, 0 };
  for (const bool alongNormals : { false, true })
  {
    auto filter = FilterType::New();
    filter->SetInput(uneven);
    filter->SetForceImage(forces);
    filter->SetScaleFactor(0.5);
    filter->SetElasticity(0.3);
    filter->SetTangentialElasticity(true);
    filter->SetRigidity(0.05);
    filter->SetConvergenceTolerance(tolerance);
    filter->SetConvergenceWindow(3);
    filter->SetConvergenceAlongNormals(alongNormals);
    filter->SetNumberOfIterations(3000);
    filter->Update();
    iterations[alongNormals] = filter->GetCurrentIteration();
    double mean = 0.0;
    double maximum = 0.0;
    MeasureDistance(filter->GetOutput(), Ellipse(center, 14.0, 14.0, 0.0), mean, maximum);
    std::cout << (alongNormals ? "along the normals: " : "whole displacement: ") << iterations[alongNormals]
              << " iterations, converged " << filter->GetConverged() << ", last largest displacement "
              << filter->GetLastMaximumDisplacement() << ", mean distance " << mean << " pixel, max " << maximum
              << std::endl;
    EXPECT_TRUE(filter->GetConverged());
    EXPECT_LE(mean, 0.1);
    EXPECT_LE(maximum, 0.3);
    if (alongNormals)
    {
      // Stopped while the points still slide.
      EXPECT_GT(filter->GetLastMaximumDisplacement(), tolerance);
      EXPECT_LE(filter->GetCurrentIteration(), 50u);
    }
  }
  EXPECT_GT(iterations[0], 4 * iterations[1]);
}

// A contour whose points are numbered far apart (a circle of 8192 points
// given in a shuffled order, its line cells following the circle) is
// renumbered internally for locality: the output, in the input's numbering,
// is the same as from the ordered circle (the balloon inflates it, the
// normals oriented from its relabelled segments).
TEST(DeformableContour, ShuffledNumberingGivesTheSameContour)
{
  constexpr unsigned int n = 8192;
  const PointType        center = Point(50.0, 50.0);
  const auto             ordered = MakeCircle(center, 30.0, n, false);
  std::vector<unsigned>  position(n); // position[k]: the point id of the circle's k-th point
  for (unsigned int k = 0; k < n; ++k)
  {
    position[k] = (k * 2731u) % n; // 2731 is prime to 8192: a permutation
  }
  auto shuffled = MeshType::New();
  for (unsigned int k = 0; k < n; ++k)
  {
    shuffled->SetPoint(position[k], ordered->GetPoint(k));
  }
  for (unsigned int k = 0; k < n; ++k)
  {
    CellType::CellAutoPointer cell;
    cell.TakeOwnership(new LineType);
    cell->SetPointId(0, position[k]);
    cell->SetPointId(1, position[(k + 1) % n]);
    shuffled->SetCell(k, cell);
  }
  std::vector<FilterType::Pointer> filters;
  for (const MeshType * input : { ordered.GetPointer(), shuffled.GetPointer() })
  {
    auto filter = FilterType::New();
    filter->SetInput(input);
    filter->SetForceImage(ZeroForces(100));
    filter->SetBalloon(0.1);
    filter->SetElasticity(0.3);
    filter->SetNumberOfIterations(3);
    filter->Update();
    filters.push_back(filter);
  }
  // The shuffled input was renumbered, the ordered one not.
  std::ostringstream printed[2];
  filters[0]->Print(printed[0]);
  filters[1]->Print(printed[1]);
  EXPECT_NE(printed[0].str().find("Renumbered: false"), std::string::npos);
  EXPECT_NE(printed[1].str().find("Renumbered: true"), std::string::npos);
  for (unsigned int k = 0; k < n; ++k)
  {
    const auto a = filters[0]->GetOutput()->GetPoint(k);
    const auto b = filters[1]->GetOutput()->GetPoint(position[k]);
    ASSERT_NEAR(a.EuclideanDistanceTo(b), 0.0, 1e-9) << "point " << k;
    ASSERT_NEAR(a.EuclideanDistanceTo(center), 30.3, 1e-3) << "point " << k;
  }
}

// The iteration contract on a 2-D mesh: ten updates of one more iteration
// with IterateFromZero off give, bit for bit, the points of one update of
// ten iterations (which fires ten IterationEvents); IterateFromZero on
// restarts from the input; 0 iterations give the input; an abort stops
// between steps, and the update after it continues from there.
TEST(DeformableContour, IterationContract)
{
  const EllipseCase c;
  const auto        circle = MakeCircle(c.center, 17.0, 200);
  auto              once = c.MakeFilter(circle, 10);
  unsigned int      events = 0;
  once->AddObserver(itk::IterationEvent(), [&](const itk::EventObject &) { ++events; });
  once->Update();
  EXPECT_EQ(events, 10u);
  EXPECT_EQ(once->GetCurrentIteration(), 10u);

  auto stepwise = c.MakeFilter(circle, 0);
  stepwise->IterateFromZeroOff();
  for (unsigned long n = 1; n <= 10; ++n)
  {
    stepwise->SetNumberOfIterations(n);
    stepwise->Update();
    EXPECT_EQ(stepwise->GetCurrentIteration(), n);
  }
  ExpectSamePoints(stepwise->GetOutput(), once->GetOutput());

  // Restart: from the input again, the same ten iterations.
  stepwise->IterateFromZeroOn();
  stepwise->Modified();
  stepwise->Update();
  EXPECT_EQ(stepwise->GetCurrentIteration(), 10u);
  ExpectSamePoints(stepwise->GetOutput(), once->GetOutput());

  auto none = c.MakeFilter(circle, 0);
  none->Update();
  ExpectSamePoints(none->GetOutput(), circle);

  // Abort after 3 iterations; the next update runs the other 7.
  auto         aborted = c.MakeFilter(circle, 10);
  unsigned int seen = 0;
  aborted->IterateFromZeroOff();
  const unsigned long tag = aborted->AddObserver(itk::IterationEvent(), [&](const itk::EventObject &) {
    if (++seen == 3)
    {
      aborted->AbortGenerateDataOn();
    }
  });
  aborted->Update();
  EXPECT_EQ(aborted->GetCurrentIteration(), 3u);
  auto three = c.MakeFilter(circle, 3);
  three->Update();
  ExpectSamePoints(aborted->GetOutput(), three->GetOutput());
  aborted->RemoveObserver(tag);
  aborted->AbortGenerateDataOff();
  aborted->Modified();
  aborted->Update();
  EXPECT_EQ(aborted->GetCurrentIteration(), 10u);
  ExpectSamePoints(aborted->GetOutput(), once->GetOutput());
}

// Bad input: an ExceptionObject whose message names the problem.
TEST(DeformableContour, BadInputRaisesClearExceptions)
{
  const auto forces = ZeroForces(40);
  const auto expectError =
    [&](const MeshType * mesh, const std::function<void(FilterType *)> & set, const std::vector<std::string> & words) {
      auto filter = FilterType::New();
      filter->SetInput(mesh);
      filter->SetForceImage(forces);
      filter->SetNumberOfIterations(2);
      set(filter);
      const std::string error = ErrorOf(filter);
      EXPECT_FALSE(error.empty());
      for (const std::string & word : words)
      {
        EXPECT_NE(error.find(word), std::string::npos) << "'" << word << "' not in: " << error;
      }
    };
  const auto nothing = [](FilterType *) {};
  const auto circle = MakeCircle(Point(20.0, 20.0), 10.0, 32);
  const auto open = MakeOpenContour(Point(10.0, 10.0), Point(30.0, 12.0), 20, 2.0);

  // A NaN point.
  {
    auto bad = MakeCircle(Point(20.0, 20.0), 10.0, 32);
    bad->SetPoint(5, Point(std::numeric_limits<double>::quiet_NaN(), 20.0));
    expectError(bad, nothing, { "non-finite", "#5" });
  }
  // Too short: a polygon of 2 points, a line from a point to itself, a
  // vertex cell.
  {
    auto bad = MeshType::New();
    bad->SetPoint(0, Point(10.0, 10.0));
    bad->SetPoint(1, Point(12.0, 10.0));
    CellType::CellAutoPointer cell;
    cell.TakeOwnership(new PolygonType);
    cell->SetPointId(0, 0);
    cell->SetPointId(1, 1);
    bad->SetCell(0, cell);
    expectError(bad, nothing, { "closed contour of 2", "at least 3" });
    // A mesh of its own (a cell set again under the same identifier would
    // not be released by the mesh).
    auto shortLine = MeshType::New();
    shortLine->SetPoint(0, Point(10.0, 10.0));
    shortLine->SetPoint(1, Point(12.0, 10.0));
    CellType::CellAutoPointer line;
    line.TakeOwnership(new LineType);
    line->SetPointId(0, 1);
    line->SetPointId(1, 1);
    shortLine->SetCell(0, line);
    expectError(shortLine, nothing, { "contour of 1", "at least 2" });
  }
  // Surface cells in a 2-D mesh.
  {
    auto                      bad = MakeCircle(Point(20.0, 20.0), 10.0, 32);
    CellType::CellAutoPointer cell;
    cell.TakeOwnership(new itk::TriangleCell<CellType>);
    cell->SetPointId(0, 0);
    cell->SetPointId(1, 1);
    cell->SetPointId(2, 2);
    bad->SetCell(1, cell);
    expectError(bad, nothing, { "Cell 1", "2-D" });
  }
  // Outward is undefined on an open contour: the balloon and the region
  // force.
  expectError(open, [](FilterType * f) { f->SetBalloon(0.1); }, { "Balloon", "open contour" });
  {
    const auto image = MakeImage(UnitGeometry(40), Point(20.0, 20.0), InsideEllipse(Point(20.0, 20.0), 8.0, 6.0, 0.0));
    expectError(open,
                [&](FilterType * f) {
                  f->SetIntensityImage(image);
                  f->SetRegionWeight(0.25);
                },
                { "RegionWeight", "open contour" });
  }
  // The 3-D triangle features.
  expectError(
    circle, [](FilterType * f) { f->SetPreventSelfIntersections(true); }, { "PreventSelfIntersections", "2-D" });
  expectError(circle, [](FilterType * f) { f->SetRemeshingEdgeLength(1.0); }, { "RemeshingEdgeLength", "2-D" });
  // A closed contour with the balloon is fine.
  {
    auto filter = FilterType::New();
    filter->SetInput(circle);
    filter->SetForceImage(forces);
    filter->SetBalloon(0.1);
    filter->SetNumberOfIterations(2);
    EXPECT_EQ(ErrorOf(filter), "");
  }
}

// The boundary of an open 3-D surface: a disk (the points of a square grid of
// unit step within radius 10 of the centre, in the plane z = 18, and the
// triangles of the grid's squares that they hold) pulled up onto a curved
// sheet (the edge of the region z < 20 + 0.02 r^2). With FixedBoundary the
// rim keeps its position bit for bit while the middle reaches the sheet; free,
// the rim moves too.
namespace
{
using Mesh3Type = itk::Mesh<double, 3, itk::DefaultStaticMeshTraits<double, 3, 3, double, double, double>>;
using Image3Type = itk::Image<float, 3>;
using Force3Type = itk::Image<itk::CovariantVector<float, 3>, 3>;
using Filter3Type = itk::DeformableMeshFilter<Mesh3Type, Force3Type>;
using EdgeType = std::pair<itk::IdentifierType, itk::IdentifierType>;

/** The boundary edges of a triangle mesh, counted independently of the
 * filter: the edges of one triangle. */
std::vector<EdgeType>
BoundaryEdges(const Mesh3Type * mesh)
{
  std::map<EdgeType, int> edgeCount;
  for (auto it = mesh->GetCells()->Begin(); it != mesh->GetCells()->End(); ++it)
  {
    const auto * ids = it.Value()->PointIdsBegin();
    for (unsigned int k = 0; k < 3; ++k)
    {
      ++edgeCount[std::minmax(ids[k], ids[(k + 1) % 3])];
    }
  }
  std::vector<EdgeType> boundary;
  for (const auto & e : edgeCount)
  {
    if (e.second == 1)
    {
      boundary.push_back(e.first);
    }
  }
  return boundary;
}

/** The points of the edges given. */
std::set<itk::IdentifierType>
EdgePoints(const std::vector<EdgeType> & edges)
{
  std::set<itk::IdentifierType> points;
  for (const auto & e : edges)
  {
    points.insert(e.first);
    points.insert(e.second);
  }
  return points;
}
} // namespace

TEST(DeformableContour, OpenSurfaceWithFixedOrFreeBoundary)
{
  const double sheetX = 20.3;
  const double sheetY = 19.8;
  const auto   sheet = [&](double x, double y) {
    return 20.0 + 0.02 * ((x - sheetX) * (x - sheetX) + (y - sheetY) * (y - sheetY));
  };
  // The sheet's image: each voxel the fraction of 8 sub-samples along z
  // below the sheet.
  auto                 image = Image3Type::New();
  Image3Type::SizeType size;
  size.Fill(40);
  image->SetRegions(size);
  image->Allocate();
  for (itk::ImageRegionIteratorWithIndex<Image3Type> it(image, image->GetBufferedRegion()); !it.IsAtEnd(); ++it)
  {
    const auto & index = it.GetIndex();
    unsigned int below = 0;
    for (unsigned int k = 0; k < 8; ++k)
    {
      below += index[2] - 0.5 + (k + 0.5) / 8.0 < sheet(index[0], index[1]) ? 1 : 0;
    }
    it.Set(100.0f * below / 8.0f);
  }
  auto forceFilter = itk::ExternalForceImageFilter<Image3Type, Force3Type>::New();
  forceFilter->SetInput(image);
  forceFilter->SetSigma(1.0);
  forceFilter->Update();

  auto                           disk = Mesh3Type::New();
  std::vector<std::vector<long>> id(21, std::vector<long>(21, -1));
  itk::IdentifierType            next = 0;
  const auto                     inDisk = [](int i, int j) { return (i - 10) * (i - 10) + (j - 10) * (j - 10) <= 100; };
  for (int i = 0; i <= 20; ++i)
  {
    for (int j = 0; j <= 20; ++j)
    {
      if (inDisk(i, j))
      {
        Mesh3Type::PointType p;
        p[0] = sheetX - 10.0 + i;
        p[1] = sheetY - 10.0 + j;
        p[2] = 18.0;
        id[i][j] = static_cast<long>(next);
        disk->SetPoint(next++, p);
      }
    }
  }
  itk::IdentifierType cells = 0;
  const auto          addTriangle = [&](long a, long b, long c) {
    if (a < 0 || b < 0 || c < 0)
    {
      return;
    }
    Mesh3Type::CellType::CellAutoPointer cell;
    cell.TakeOwnership(new itk::TriangleCell<Mesh3Type::CellType>);
    cell->SetPointId(0, a);
    cell->SetPointId(1, b);
    cell->SetPointId(2, c);
    disk->SetCell(cells++, cell);
  };
  for (int i = 0; i < 20; ++i)
  {
    for (int j = 0; j < 20; ++j)
    {
      addTriangle(id[i][j], id[i + 1][j], id[i + 1][j + 1]);
      addTriangle(id[i][j], id[i + 1][j + 1], id[i][j + 1]);
    }
  }
  // The rim, counted independently: the points of edges of one triangle.
  const std::vector<EdgeType>         rimEdges = BoundaryEdges(disk);
  const std::set<itk::IdentifierType> rim = EdgePoints(rimEdges);
  ASSERT_GT(rim.size(), 30u);
  const itk::IdentifierType middle = static_cast<itk::IdentifierType>(id[10][10]);

  for (const bool fixed : { true, false })
  {
    auto filter = Filter3Type::New();
    filter->SetInput(disk);
    filter->SetForceImage(forceFilter->GetOutput());
    filter->SetScaleFactor(0.5);
    filter->SetElasticity(0.3);
    filter->SetFixedBoundary(fixed);
    filter->SetNumberOfIterations(200);
    filter->Update();
    EXPECT_EQ(filter->GetNumberOfBoundaryVertices(), rim.size());
    const Mesh3Type * out = filter->GetOutput();
    EXPECT_NEAR(out->GetPoint(middle)[2], sheet(out->GetPoint(middle)[0], out->GetPoint(middle)[1]), 0.3)
      << (fixed ? "fixed" : "free");
    double rimMotion = 0.0;
    for (const auto i : rim)
    {
      if (fixed)
      {
        for (unsigned int k = 0; k < 3; ++k)
        {
          ASSERT_EQ(out->GetPoint(i)[k], disk->GetPoint(i)[k]) << "rim point " << i;
        }
      }
      rimMotion = std::max(rimMotion, out->GetPoint(i).EuclideanDistanceTo(disk->GetPoint(i)));
    }
    if (!fixed)
    {
      EXPECT_GE(rimMotion, 1.0);
    }
  }

  // With remeshing (edges brought near 0.7 mm every 10 iterations): the
  // input's rim points are still there, bit for bit, and every boundary
  // vertex of the output (edges of one triangle, counted here) lies on the
  // input's rim polygon.
  auto filter = Filter3Type::New();
  filter->SetInput(disk);
  filter->SetForceImage(forceFilter->GetOutput());
  filter->SetScaleFactor(0.5);
  filter->SetElasticity(0.3);
  filter->SetFixedBoundary(true);
  filter->SetRemeshingEdgeLength(0.7);
  filter->SetNumberOfIterations(100);
  filter->Update();
  const Mesh3Type * out = filter->GetOutput();
  EXPECT_GE(filter->GetNumberOfRemeshings(), 1u);
  EXPECT_GT(out->GetNumberOfPoints(), disk->GetNumberOfPoints());
  std::set<std::array<double, 3>> outputPoints;
  for (auto it = out->GetPoints()->Begin(); it != out->GetPoints()->End(); ++it)
  {
    outputPoints.insert({ it.Value()[0], it.Value()[1], it.Value()[2] });
  }
  for (const auto i : rim)
  {
    const auto & p = disk->GetPoint(i);
    EXPECT_EQ(outputPoints.count({ p[0], p[1], p[2] }), 1u) << "rim point " << i;
  }
  const std::set<itk::IdentifierType> outputRim = EdgePoints(BoundaryEdges(out));
  EXPECT_EQ(filter->GetNumberOfBoundaryVertices(), outputRim.size());
  EXPECT_GT(outputRim.size(), rim.size());
  for (const auto i : outputRim)
  {
    const auto & p = out->GetPoint(i);
    double       nearest = std::numeric_limits<double>::max();
    for (const auto & e : rimEdges)
    {
      const auto   a = disk->GetPoint(e.first);
      const auto   b = disk->GetPoint(e.second);
      const auto   ab = b - a;
      const double t = std::max(0.0, std::min(1.0, ((p - a) * ab) / (ab * ab)));
      nearest = std::min(nearest, (p - (a + ab * t)).GetNorm());
    }
    EXPECT_LE(nearest, 1e-9) << "output boundary point " << i;
  }
}
