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

// The VTK faces in 2-D: contours (vtkPolyData lines and polylines) over a
// 2-D vtkImageData (nx x ny x 1), through vtkExternalForceField and
// vtkDeformableMesh. Known answers (a circle pulled onto an ellipse, in
// pixels and in physical units with a rotated, anisotropic grid), exact
// delegation to the 2-D ITK filters, fixed ends of an open contour, the
// iteration contract, the time series, and the inputs that are refused.

#include "edmMeshBridge.h"
#include "vtkDeformableMesh.h"
#include "vtkExternalForceField.h"
#include "vtkIterationSeriesWriter.h"
#include "vtkIterativePolyDataAlgorithmInternals.h"

#include "itkCommand.h"
#include "itkDeformableMeshFilter.h"
#include "itkExternalForceImageFilter.h"

#include "vtkCallbackCommand.h"
#include "vtkCellArray.h"
#include "vtkCommand.h"
#include "vtkDoubleArray.h"
#include "vtkFloatArray.h"
#include "vtkImageData.h"
#include "vtkMatrix3x3.h"
#include "vtkNew.h"
#include "vtkObjectFactory.h"
#include "vtkPointData.h"
#include "vtkPoints.h"
#include "vtkPolyData.h"
#include "vtkSphereSource.h"
#include "vtkTrivialProducer.h"
#include "vtkXMLPolyDataReader.h"

#include "gtest/gtest.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>
#include <vector>

namespace
{
using ContourMeshType = vtkIterativePolyDataAlgorithmInternals::ContourMeshType;
using ImageType = itk::Image<float, 2>;
using ForceImageType = itk::Image<itk::CovariantVector<float, 2>, 2>;
using ContourFilterType = itk::DeformableMeshFilter<ContourMeshType, ForceImageType>;

constexpr double pi = 3.14159265358979323846;

/** Counts the steps of the 2-D ITK filter inside vtkDeformableMesh. */
class CountingDeformableMesh : public vtkDeformableMesh
{
public:
  static CountingDeformableMesh *
  New()
  {
    VTK_STANDARD_NEW_BODY(CountingDeformableMesh);
  }
  vtkTypeMacro(CountingDeformableMesh, vtkDeformableMesh);

  int Steps = 0;
  int
  TakeSteps()
  {
    const int steps = this->Steps;
    this->Steps = 0;
    return steps;
  }

protected:
  CountingDeformableMesh()
  {
    this->Internals->ContourFilter->AddObserver(itk::IterationEvent(),
                                                [this](const itk::EventObject &) { ++this->Steps; });
  }
  ~CountingDeformableMesh() override = default;
};

/** Records the error messages of a VTK object. */
class ErrorRecorder
{
public:
  explicit ErrorRecorder(vtkObject * object)
  {
    m_Callback->SetClientData(this);
    m_Callback->SetCallback([](vtkObject *, unsigned long, void * clientData, void * callData) {
      auto * self = static_cast<ErrorRecorder *>(clientData);
      self->m_Messages += callData != nullptr ? static_cast<const char *>(callData) : "";
      self->m_Messages += "\n";
      ++self->m_Count;
    });
    object->AddObserver(vtkCommand::ErrorEvent, m_Callback);
  }
  int
  Count() const
  {
    return m_Count;
  }
  /** The messages since the last call. */
  std::string
  Take()
  {
    std::string messages;
    messages.swap(m_Messages);
    return messages;
  }

private:
  vtkNew<vtkCallbackCommand> m_Callback;
  std::string                m_Messages;
  int                        m_Count{ 0 };
};

/** An ellipse of centre c, semi-axes a and b, the a-axis at angle radians
 * from x, in physical space. */
struct Ellipse
{
  double center[2];
  double a;
  double b;
  double angle;

  /** The point in the ellipse's own frame. */
  void
  ToFrame(const double p[2], double & u, double & v) const
  {
    const double dx = p[0] - center[0];
    const double dy = p[1] - center[1];
    u = std::cos(angle) * dx + std::sin(angle) * dy;
    v = -std::sin(angle) * dx + std::cos(angle) * dy;
  }
  bool
  Inside(const double p[2]) const
  {
    double u;
    double v;
    this->ToFrame(p, u, v);
    return (u / a) * (u / a) + (v / b) * (v / b) <= 1.0;
  }
  /** Euclidean distance to the curve: the closest point is r^2 z / (t + r^2)
   * for the largest root t of sum (r_k z_k / (t + r_k^2))^2 = 1, found by
   * bisection (exact to rounding). */
  double
  Distance(const double p[2]) const
  {
    double u;
    double v;
    this->ToFrame(p, u, v);
    const double z[2] = { std::abs(u), std::abs(v) };
    const double r[2] = { a, b };
    auto         g = [&](double t) {
      double sum = 0.0;
      for (int k = 0; k < 2; ++k)
      {
        const double q = r[k] * z[k] / (t + r[k] * r[k]);
        sum += q * q;
      }
      return sum - 1.0;
    };
    double low = -std::min(a * a, b * b);
    double high = std::max(a, b) * std::hypot(z[0], z[1]) + 1.0;
    for (int step = 0; step < 200; ++step)
    {
      const double middle = 0.5 * (low + high);
      (g(middle) > 0.0 ? low : high) = middle;
    }
    const double t = 0.5 * (low + high);
    double       closest[2];
    for (int k = 0; k < 2; ++k)
    {
      closest[k] = std::min(r[k] * r[k] * z[k] / (t + r[k] * r[k]), r[k]);
    }
    // On the major axis near the centre the root is -b^2 itself (0 / 0 above):
    // the closest point is then off the axis, on the ellipse.
    for (int k = 0; k < 2; ++k)
    {
      if (!std::isfinite(closest[k]))
      {
        const double other = closest[1 - k] / r[1 - k];
        closest[k] = r[k] * std::sqrt(std::max(0.0, 1.0 - other * other));
      }
    }
    return std::hypot(z[0] - closest[0], z[1] - closest[1]);
  }
};

/** Mean and largest distance of the points of a polydata to an ellipse. */
void
MeasureDistance(vtkPolyData * polyData, const Ellipse & ellipse, double & mean, double & maximum)
{
  mean = 0.0;
  maximum = 0.0;
  for (vtkIdType i = 0; i < polyData->GetNumberOfPoints(); ++i)
  {
    double p[3];
    polyData->GetPoint(i, p);
    const double d = ellipse.Distance(p);
    mean += d;
    maximum = std::max(maximum, d);
  }
  mean /= static_cast<double>(polyData->GetNumberOfPoints());
}

/** A 2-D image's geometry: nx x ny x 1 points, origin (z: the plane),
 * spacing, and an in-plane rotation of its axes. */
struct Geometry
{
  int    size[2] = { 72, 72 };
  double origin[3] = { 0.0, 0.0, 0.0 };
  double spacing[2] = { 1.0, 1.0 };
  double rotation = 0.0;
};

/** A 2-D vtkImageData, anti-aliased: each pixel holds 100 times the fraction
 * of its 16 x 16 sub-samples inside one of the ellipses (point array
 * "Intensity", the active scalars). */
vtkSmartPointer<vtkImageData>
MakeImage(const Geometry & g, const std::vector<Ellipse> & ellipses)
{
  auto image = vtkSmartPointer<vtkImageData>::New();
  image->SetDimensions(g.size[0], g.size[1], 1);
  image->SetOrigin(g.origin);
  image->SetSpacing(g.spacing[0], g.spacing[1], 1.0);
  vtkNew<vtkMatrix3x3> direction;
  direction->SetElement(0, 0, std::cos(g.rotation));
  direction->SetElement(0, 1, -std::sin(g.rotation));
  direction->SetElement(1, 0, std::sin(g.rotation));
  direction->SetElement(1, 1, std::cos(g.rotation));
  image->SetDirectionMatrix(direction);
  vtkNew<vtkFloatArray> values;
  values->SetName("Intensity");
  values->SetNumberOfTuples(image->GetNumberOfPoints());
  constexpr int sub = 16;
  for (int j = 0; j < g.size[1]; ++j)
  {
    for (int i = 0; i < g.size[0]; ++i)
    {
      int count = 0;
      for (int a = 0; a < sub; ++a)
      {
        for (int b = 0; b < sub; ++b)
        {
          double p[3];
          image->TransformContinuousIndexToPhysicalPoint(i - 0.5 + (a + 0.5) / sub, j - 0.5 + (b + 0.5) / sub, 0.0, p);
          count += std::any_of(ellipses.begin(), ellipses.end(), [&p](const Ellipse & e) { return e.Inside(p); });
        }
      }
      values->SetValue(i + g.size[0] * j, 100.0f * static_cast<float>(count) / (sub * sub));
    }
  }
  image->GetPointData()->SetScalars(values);
  return image;
}

/** A circle of n points around (cx, cy) at height z: one closed polyline
 * (its first point repeated at its end) or n two-point lines. */
vtkSmartPointer<vtkPolyData>
MakeCircle(double cx, double cy, double radius, int n, double z, bool polyline = true)
{
  auto              polyData = vtkSmartPointer<vtkPolyData>::New();
  vtkNew<vtkPoints> points;
  points->SetDataTypeToDouble();
  for (int k = 0; k < n; ++k)
  {
    const double t = 2.0 * pi * k / n;
    points->InsertNextPoint(cx + radius * std::cos(t), cy + radius * std::sin(t), z);
  }
  vtkNew<vtkCellArray> lines;
  if (polyline)
  {
    lines->InsertNextCell(n + 1);
    for (int k = 0; k <= n; ++k)
    {
      lines->InsertCellPoint(k % n);
    }
  }
  else
  {
    for (int k = 0; k < n; ++k)
    {
      const vtkIdType segment[2] = { k, (k + 1) % n };
      lines->InsertNextCell(2, segment);
    }
  }
  polyData->SetPoints(points);
  polyData->SetLines(lines);
  return polyData;
}

/** An open polyline of n points from (ax, ay) to (bx, by), bowed sideways by
 * bow at its middle (a parabola), at height z. */
vtkSmartPointer<vtkPolyData>
MakeOpenContour(double ax, double ay, double bx, double by, int n, double bow, double z)
{
  auto              polyData = vtkSmartPointer<vtkPolyData>::New();
  vtkNew<vtkPoints> points;
  points->SetDataTypeToDouble();
  const double         dx = bx - ax;
  const double         dy = by - ay;
  const double         length = std::hypot(dx, dy);
  vtkNew<vtkCellArray> lines;
  lines->InsertNextCell(n);
  for (int k = 0; k < n; ++k)
  {
    const double s = static_cast<double>(k) / (n - 1);
    const double side = bow * 4.0 * s * (1.0 - s);
    points->InsertNextPoint(ax + s * dx - side * dy / length, ay + s * dy + side * dx / length, z);
    lines->InsertCellPoint(k);
  }
  polyData->SetPoints(points);
  polyData->SetLines(lines);
  return polyData;
}

/** The points of a vtkPolyData, as doubles. */
std::vector<double>
Coordinates(vtkPolyData * polyData)
{
  std::vector<double> x(3 * polyData->GetNumberOfPoints());
  for (vtkIdType i = 0; i < polyData->GetNumberOfPoints(); ++i)
  {
    polyData->GetPoint(i, &x[3 * i]);
  }
  return x;
}

/** The test case of the ITK filter's known answer: an ellipse of semi-axes
 * (20, 14) pixels centred at (35.3, 36.1) in a 72 x 72 image, the plane
 * z = -3.25, and a circle of radius 17 and 200 points at its centre. */
const Ellipse    TestEllipse{ { 35.3, 36.1 }, 20.0, 14.0, 0.0 };
constexpr double PlaneZ = -3.25;

Geometry
TestGeometry()
{
  Geometry g;
  g.origin[2] = PlaneZ;
  return g;
}

/** vtkExternalForceField (sigma 1 pixel) of an image, updated. */
vtkSmartPointer<vtkExternalForceField>
MakeForces(vtkImageData * image)
{
  auto forces = vtkSmartPointer<vtkExternalForceField>::New();
  forces->SetInputData(image);
  forces->SetSigma(1.0);
  forces->Update();
  return forces;
}

/** The 2-D ITK filter run directly on the same data (the reference). */
ContourFilterType::Pointer
ReferenceFilter(vtkPolyData * contour, vtkImageData * image)
{
  auto intensity = edm::ImageDataToImage<ImageType>(image, image->GetPointData()->GetArray("Intensity"));
  auto forces = itk::ExternalForceImageFilter<ImageType, ForceImageType>::New();
  forces->SetInput(intensity);
  forces->SetSigma(1.0);
  forces->Update();
  edm::MeshBridgeOptions options;
  options.PointData = false;
  options.CellData = false;
  options.PolyLinesAsSegments = true;
  auto filter = ContourFilterType::New();
  filter->SetInput(edm::PolyDataToMesh<ContourMeshType>(contour, options));
  filter->SetForceImage(forces->GetOutput());
  return filter;
}
} // namespace

// The measure: points at known distances from the ellipse.
TEST(VTKDeformableContour, DistanceToTheEllipseKnownAnswers)
{
  const Ellipse e{ { 0.0, 0.0 }, 20.0, 14.0, 0.0 };
  const double  onAxis[2] = { 23.0, 0.0 };
  const double  inside[2] = { 0.0, 10.0 };
  const double  centre[2] = { 0.0, 0.0 };
  EXPECT_NEAR(e.Distance(onAxis), 3.0, 1e-9);
  EXPECT_NEAR(e.Distance(inside), 4.0, 1e-9);
  EXPECT_NEAR(e.Distance(centre), 14.0, 1e-9);
  const Ellipse rotated{ { 5.0, -2.0 }, 20.0, 14.0, 0.5 };
  const double  rotatedPoint[2] = { 5.0 + 25.0 * std::cos(0.5), -2.0 + 25.0 * std::sin(0.5) };
  EXPECT_NEAR(rotated.Distance(rotatedPoint), 5.0, 1e-9);
}

// vtkExternalForceField on a 2-D image is the 2-D ITK filter: the same
// in-plane force, a third component of 0, the input's geometry (its plane z).
TEST(VTKDeformableContour, ForceFieldOfA2DImageIsThe2DITKFilter)
{
  Geometry g = TestGeometry();
  g.spacing[0] = 0.75;
  g.rotation = 0.3;
  const auto     image = MakeImage(g, { TestEllipse });
  const auto     forces = MakeForces(image);
  vtkImageData * output = forces->GetOutput();
  ASSERT_EQ(output->GetNumberOfPoints(), image->GetNumberOfPoints());
  EXPECT_EQ(output->GetOrigin()[2], PlaneZ);
  EXPECT_EQ(output->GetDirectionMatrix()->GetElement(0, 1), image->GetDirectionMatrix()->GetElement(0, 1));
  vtkDataArray * force = output->GetPointData()->GetVectors();
  ASSERT_NE(force, nullptr);
  EXPECT_STREQ(force->GetName(), "Force");
  ASSERT_EQ(force->GetNumberOfComponents(), 3);
  ASSERT_NE(output->GetPointData()->GetArray("Intensity"), nullptr);

  auto intensity = edm::ImageDataToImage<ImageType>(image, image->GetPointData()->GetArray("Intensity"));
  auto reference = itk::ExternalForceImageFilter<ImageType, ForceImageType>::New();
  reference->SetInput(intensity);
  reference->SetSigma(1.0);
  reference->Update();
  const auto * buffer = reference->GetOutput()->GetBufferPointer();
  double       largest = 0.0;
  for (vtkIdType i = 0; i < output->GetNumberOfPoints(); ++i)
  {
    ASSERT_EQ(force->GetComponent(i, 0), buffer[i][0]) << i;
    ASSERT_EQ(force->GetComponent(i, 1), buffer[i][1]) << i;
    ASSERT_EQ(force->GetComponent(i, 2), 0.0) << i;
    largest = std::max(largest, std::hypot(force->GetComponent(i, 0), force->GetComponent(i, 1)));
  }
  EXPECT_NEAR(largest, 1.0, 1e-6); // normalised
}

// A circle of 200 points pulled onto the edge of the ellipse, through
// vtkExternalForceField and vtkDeformableMesh (sigma 1 pixel, ScaleFactor
// 0.5, Elasticity 0.3, 400 iterations): within 0.1 pixel on average and 0.3
// at most of the analytic curve, as the ITK filter's known answer, the points
// in the image's plane, and exactly the 2-D ITK filter's result. The same from
// a circle of two-point lines.
TEST(VTKDeformableContour, CircleReachesAnEllipse)
{
  const auto image = MakeImage(TestGeometry(), { TestEllipse });
  const auto forces = MakeForces(image);
  for (const bool polyline : { true, false })
  {
    const auto circle = MakeCircle(TestEllipse.center[0], TestEllipse.center[1], 17.0, 200, 0.0, polyline);
    vtkNew<CountingDeformableMesh> deformable;
    deformable->SetInputData(circle);
    deformable->SetForceImageConnection(forces->GetOutputPort());
    deformable->SetScaleFactor(0.5);
    deformable->SetElasticity(0.3);
    deformable->SetNumberOfIterations(400);
    deformable->Update();
    vtkPolyData * output = deformable->GetOutput();
    EXPECT_EQ(deformable->TakeSteps(), 400);
    EXPECT_EQ(deformable->GetMeshDimension(), 2);
    EXPECT_EQ(deformable->GetCurrentIteration(), 400);
    EXPECT_EQ(deformable->GetNumberOfClosedContours(), 1);
    EXPECT_EQ(deformable->GetNumberOfOpenContours(), 0);
    ASSERT_EQ(output->GetNumberOfPoints(), 200);
    EXPECT_EQ(output->GetNumberOfLines(), circle->GetNumberOfLines());
    EXPECT_EQ(output->GetNumberOfPolys(), 0);
    ASSERT_NE(output->GetPointData()->GetArray("DisplacementMagnitude"), nullptr);

    double mean = 0.0;
    double maximum = 0.0;
    MeasureDistance(circle, TestEllipse, mean, maximum);
    EXPECT_GT(mean, 1.0);
    MeasureDistance(output, TestEllipse, mean, maximum);
    std::cout << (polyline ? "closed polyline" : "two-point lines") << ": mean " << mean << " pixel, max " << maximum
              << " pixel from the ellipse" << std::endl;
    EXPECT_LE(mean, 0.1);
    EXPECT_LE(maximum, 0.3);

    auto reference = ReferenceFilter(circle, image);
    reference->SetScaleFactor(0.5);
    reference->SetElasticity(0.3);
    reference->SetNumberOfIterations(400);
    reference->Update();
    const auto * points = reference->GetOutput()->GetPoints();
    ASSERT_EQ(static_cast<vtkIdType>(points->Size()), output->GetNumberOfPoints());
    for (vtkIdType i = 0; i < output->GetNumberOfPoints(); ++i)
    {
      double p[3];
      output->GetPoint(i, p);
      ASSERT_EQ(p[0], points->ElementAt(i)[0]) << i;
      ASSERT_EQ(p[1], points->ElementAt(i)[1]) << i;
      ASSERT_EQ(p[2], PlaneZ) << i;
    }
  }
}

// The same physical ellipse rotated by 0.3 rad, imaged with pixels of 0.6 x
// 1.0 mm, a direction rotated by 0.5 rad and an origin away from 0: the
// tolerances in units of the smallest spacing (0.6 mm).
TEST(VTKDeformableContour, CircleReachesARotatedEllipseInPhysicalUnits)
{
  Geometry g;
  g.size[0] = 110;
  g.size[1] = 70;
  g.spacing[0] = 0.6;
  g.spacing[1] = 1.0;
  g.origin[0] = 10.0;
  g.origin[1] = -25.0;
  g.origin[2] = 4.5;
  g.rotation = 0.5;
  vtkNew<vtkImageData> reference;
  reference->SetOrigin(g.origin);
  reference->SetSpacing(g.spacing[0], g.spacing[1], 1.0);
  reference->SetDirectionMatrix(std::cos(0.5), -std::sin(0.5), 0.0, std::sin(0.5), std::cos(0.5), 0.0, 0.0, 0.0, 1.0);
  double center[3];
  reference->TransformContinuousIndexToPhysicalPoint(54.3, 34.6, 0.0, center);
  const Ellipse ellipse{ { center[0], center[1] }, 20.0, 14.0, 0.3 };
  const double  pixel = 0.6;
  const auto    image = MakeImage(g, { ellipse });
  const auto    forces = MakeForces(image);
  const auto    circle = MakeCircle(center[0], center[1], 17.0, 200, 0.0);

  vtkNew<vtkDeformableMesh> deformable;
  deformable->SetInputData(circle);
  deformable->SetForceImageConnection(forces->GetOutputPort());
  deformable->SetScaleFactor(0.5);
  deformable->SetElasticity(0.3);
  deformable->SetNumberOfIterations(400);
  deformable->Update();
  ASSERT_EQ(deformable->GetOutput()->GetNumberOfPoints(), 200);
  double mean = 0.0;
  double maximum = 0.0;
  MeasureDistance(deformable->GetOutput(), ellipse, mean, maximum);
  std::cout << "rotated, anisotropic: mean " << mean / pixel << " pixel, max " << maximum / pixel << " pixel"
            << std::endl;
  EXPECT_LE(mean, 0.1 * pixel);
  EXPECT_LE(maximum, 0.3 * pixel);
  EXPECT_EQ(deformable->GetOutput()->GetBounds()[4], 4.5);
  EXPECT_EQ(deformable->GetOutput()->GetBounds()[5], 4.5);
}

// Two closed contours and an open one in one polydata, each over its own
// ellipse: the closed ones end on their ellipses, the open one keeps its ends
// with FixedBoundary.
TEST(VTKDeformableContour, SeveralContoursInOnePolydata)
{
  Geometry g;
  g.size[0] = 120;
  g.size[1] = 72;
  const Ellipse left{ { 32.2, 35.7 }, 20.0, 14.0, 0.0 };
  const Ellipse right{ { 86.6, 36.3 }, 18.0, 13.0, 0.4 };
  const auto    image = MakeImage(g, { left, right });
  const auto    forces = MakeForces(image);

  // The left circle as a closed polyline, the right one as two-point lines,
  // and an open polyline across the bottom of the left ellipse.
  const auto a = MakeCircle(left.center[0], left.center[1], 17.0, 160, 0.0, true);
  const auto b = MakeCircle(right.center[0], right.center[1], 15.5, 140, 0.0, false);
  const auto c = MakeOpenContour(
    left.center[0] - 12.0, left.center[1] - 9.0, left.center[0] + 12.0, left.center[1] - 9.0, 41, -3.0, 0.0);
  vtkNew<vtkPolyData>  contours;
  vtkNew<vtkPoints>    points;
  vtkNew<vtkCellArray> lines;
  points->SetDataTypeToDouble();
  for (vtkPolyData * part : { a.GetPointer(), b.GetPointer(), c.GetPointer() })
  {
    const vtkIdType offset = points->GetNumberOfPoints();
    for (vtkIdType i = 0; i < part->GetNumberOfPoints(); ++i)
    {
      points->InsertNextPoint(part->GetPoint(i));
    }
    vtkIdType         n = 0;
    const vtkIdType * ids = nullptr;
    for (part->GetLines()->InitTraversal(); part->GetLines()->GetNextCell(n, ids);)
    {
      lines->InsertNextCell(n);
      for (vtkIdType k = 0; k < n; ++k)
      {
        lines->InsertCellPoint(ids[k] + offset);
      }
    }
  }
  contours->SetPoints(points);
  contours->SetLines(lines);

  vtkNew<vtkDeformableMesh> deformable;
  deformable->SetInputData(contours);
  deformable->SetForceImageConnection(forces->GetOutputPort());
  deformable->SetScaleFactor(0.5);
  deformable->SetElasticity(0.3);
  deformable->FixedBoundaryOn();
  deformable->SetNumberOfIterations(400);
  deformable->Update();
  vtkPolyData * output = deformable->GetOutput();
  ASSERT_EQ(output->GetNumberOfPoints(), 160 + 140 + 41);
  EXPECT_EQ(deformable->GetNumberOfClosedContours(), 2);
  EXPECT_EQ(deformable->GetNumberOfOpenContours(), 1);
  const struct
  {
    const char *    name;
    const Ellipse & ellipse;
    vtkIdType       first;
    vtkIdType       count;
  } parts[] = { { "left, closed polyline", left, 0, 160 }, { "right, two-point lines", right, 160, 140 } };
  for (const auto & part : parts)
  {
    double mean = 0.0;
    double maximum = 0.0;
    for (vtkIdType i = part.first; i < part.first + part.count; ++i)
    {
      double p[3];
      output->GetPoint(i, p);
      const double d = part.ellipse.Distance(p);
      mean += d / static_cast<double>(part.count);
      maximum = std::max(maximum, d);
    }
    std::cout << part.name << ": mean " << mean << " pixel, max " << maximum << " pixel" << std::endl;
    EXPECT_LE(mean, 0.1) << part.name;
    EXPECT_LE(maximum, 0.3) << part.name;
  }
  for (const vtkIdType end : { vtkIdType{ 300 }, vtkIdType{ 340 } })
  {
    double p[3];
    double q[3];
    output->GetPoint(end, p);
    contours->GetPoint(end, q);
    EXPECT_EQ(p[0], q[0]) << end;
    EXPECT_EQ(p[1], q[1]) << end;
  }
}

// An open contour 2 pixels inside the bottom of the ellipse: with
// FixedBoundary its two ends keep their coordinates bit for bit (and their
// displacement is 0) while its middle reaches the edge; without, the ends
// move (the one-sided membrane force pulls them inward).
TEST(VTKDeformableContour, OpenContourWithFixedBoundaryKeepsItsEnds)
{
  const auto image = MakeImage(TestGeometry(), { TestEllipse });
  const auto forces = MakeForces(image);
  const auto open = MakeOpenContour(TestEllipse.center[0] - 12.0,
                                    TestEllipse.center[1] - 9.0,
                                    TestEllipse.center[0] + 12.0,
                                    TestEllipse.center[1] - 9.0,
                                    41,
                                    -3.0,
                                    PlaneZ);
  for (const bool fixed : { true, false })
  {
    vtkNew<vtkDeformableMesh> deformable;
    deformable->SetInputData(open);
    deformable->SetForceImageConnection(forces->GetOutputPort());
    deformable->SetScaleFactor(0.5);
    deformable->SetElasticity(0.3);
    deformable->SetFixedBoundary(fixed);
    deformable->SetNumberOfIterations(300);
    deformable->Update();
    vtkPolyData * output = deformable->GetOutput();
    ASSERT_EQ(output->GetNumberOfPoints(), 41) << (fixed ? "fixed" : "free");
    EXPECT_EQ(deformable->GetNumberOfOpenContours(), 1);
    EXPECT_EQ(deformable->GetNumberOfClosedContours(), 0);
    double middle[3];
    output->GetPoint(20, middle);
    EXPECT_LE(TestEllipse.Distance(middle), 0.3) << (fixed ? "fixed" : "free");
    vtkDataArray * displacement = output->GetPointData()->GetArray("DisplacementMagnitude");
    ASSERT_NE(displacement, nullptr);
    for (const vtkIdType end : { vtkIdType{ 0 }, vtkIdType{ 40 } })
    {
      double p[3];
      double q[3];
      output->GetPoint(end, p);
      open->GetPoint(end, q);
      if (fixed)
      {
        EXPECT_EQ(p[0], q[0]) << "end " << end;
        EXPECT_EQ(p[1], q[1]) << "end " << end;
        EXPECT_EQ(p[2], q[2]) << "end " << end;
        EXPECT_EQ(displacement->GetComponent(end, 0), 0.0) << "end " << end;
      }
      else
      {
        EXPECT_GE(std::hypot(p[0] - q[0], p[1] - q[1]), 1.0) << "end " << end;
      }
    }
  }
}

// The iteration contract in 2-D: 0 iterations give the input back; with
// IterateFromZero off one more iteration runs one step, and ten steps equal
// ten iterations from zero; fewer iterations, a new input or a change of
// dimension restart; the 3-D model runs again afterwards.
TEST(VTKDeformableContour, IterationContractStepByStep)
{
  const auto image = MakeImage(TestGeometry(), { TestEllipse });
  const auto forces = MakeForces(image);
  const auto circle = MakeCircle(TestEllipse.center[0], TestEllipse.center[1], 17.0, 120, PlaneZ);

  vtkNew<CountingDeformableMesh> deformable;
  deformable->SetInputData(circle);
  deformable->SetForceImageConnection(forces->GetOutputPort());
  deformable->SetScaleFactor(0.5);
  deformable->SetElasticity(0.3);
  deformable->SetRigidity(0.05);
  deformable->IterateFromZeroOff();
  deformable->SetNumberOfIterations(0);
  deformable->Update();
  EXPECT_EQ(Coordinates(deformable->GetOutput()), Coordinates(circle));
  EXPECT_EQ(deformable->TakeSteps(), 0);
  std::vector<std::vector<double>> steps;
  for (int n = 1; n <= 10; ++n)
  {
    deformable->SetNumberOfIterations(n);
    deformable->Update();
    EXPECT_EQ(deformable->TakeSteps(), 1) << "iteration " << n;
    EXPECT_EQ(deformable->GetCurrentIteration(), n);
    steps.push_back(Coordinates(deformable->GetOutput()));
  }
  EXPECT_NE(steps.front(), Coordinates(circle));

  vtkNew<vtkDeformableMesh> fromZero;
  fromZero->SetInputData(circle);
  fromZero->SetForceImageConnection(forces->GetOutputPort());
  fromZero->SetScaleFactor(0.5);
  fromZero->SetElasticity(0.3);
  fromZero->SetRigidity(0.05);
  fromZero->SetNumberOfIterations(10);
  fromZero->Update();
  EXPECT_EQ(Coordinates(fromZero->GetOutput()), steps.back());

  // Fewer iterations than done: a restart, which runs them all.
  deformable->SetNumberOfIterations(4);
  deformable->Update();
  EXPECT_EQ(deformable->TakeSteps(), 4);
  EXPECT_EQ(Coordinates(deformable->GetOutput()), steps[3]);
  // IterateFromZero: every update runs everything again.
  deformable->IterateFromZeroOn();
  deformable->Modified();
  deformable->Update();
  EXPECT_EQ(deformable->TakeSteps(), 4);
  deformable->IterateFromZeroOff();
  // A modified input restarts.
  circle->Modified();
  deformable->SetNumberOfIterations(5);
  deformable->Update();
  EXPECT_EQ(deformable->TakeSteps(), 5);
  EXPECT_EQ(Coordinates(deformable->GetOutput()), steps[4]);

  // A surface over a 3-D image: the 3-D model, from its input; then the
  // contour again: a restart in 2-D.
  vtkNew<vtkImageData> volume;
  volume->SetDimensions(16, 16, 16);
  vtkNew<vtkFloatArray> zero;
  zero->SetName("Force");
  zero->SetNumberOfComponents(3);
  zero->SetNumberOfTuples(volume->GetNumberOfPoints());
  zero->Fill(0.0);
  volume->GetPointData()->SetVectors(zero);
  vtkNew<vtkSphereSource> sphere;
  sphere->SetCenter(8.0, 8.0, 8.0);
  sphere->SetRadius(4.0);
  sphere->Update();
  deformable->SetInputData(sphere->GetOutput());
  deformable->SetForceImageData(volume);
  deformable->Update();
  EXPECT_EQ(deformable->GetMeshDimension(), 3);
  EXPECT_EQ(deformable->GetCurrentIteration(), 5);
  EXPECT_EQ(deformable->GetOutput()->GetNumberOfPoints(), sphere->GetOutput()->GetNumberOfPoints());
  deformable->SetInputData(circle);
  deformable->SetForceImageConnection(forces->GetOutputPort());
  deformable->SetNumberOfIterations(6);
  deformable->Update();
  EXPECT_EQ(deformable->GetMeshDimension(), 2);
  EXPECT_EQ(deformable->TakeSteps(), 6);
  deformable->SetNumberOfIterations(7);
  deformable->Update();
  EXPECT_EQ(deformable->TakeSteps(), 1);
}

// vtkIterationSeriesWriter drives a 2-D model as a 3-D one: every 5th
// iteration and the last, each file holding the contour's lines in the
// image's plane.
TEST(VTKDeformableContour, SeriesWriterWritesAContourSeries)
{
  const auto image = MakeImage(TestGeometry(), { TestEllipse });
  const auto forces = MakeForces(image);
  const auto circle = MakeCircle(TestEllipse.center[0], TestEllipse.center[1], 17.0, 100, 0.0);

  vtkNew<vtkDeformableMesh> deformable;
  deformable->SetInputData(circle);
  deformable->SetForceImageConnection(forces->GetOutputPort());
  deformable->SetScaleFactor(0.5);
  deformable->SetElasticity(0.3);
  const std::string                collection = std::string(EDM_TEST_OUTPUT_DIRECTORY) + "/contour-series.pvd";
  vtkNew<vtkIterationSeriesWriter> writer;
  writer->SetFileName(collection.c_str());
  writer->SetAlgorithm(deformable);
  writer->SetInterval(5);
  writer->SetNumberOfIterations(12);
  ASSERT_EQ(writer->Write(), 1);
  ASSERT_EQ(writer->GetNumberOfWrittenFiles(), 4);
  const int expected[] = { 0, 5, 10, 12 };
  for (int k = 0; k < 4; ++k)
  {
    EXPECT_EQ(writer->GetWrittenIteration(k), expected[k]);
    vtkNew<vtkXMLPolyDataReader> reader;
    reader->SetFileName(writer->GetWrittenFileName(k));
    reader->Update();
    vtkPolyData * written = reader->GetOutput();
    ASSERT_EQ(written->GetNumberOfPoints(), 100) << k;
    EXPECT_EQ(written->GetNumberOfLines(), 1) << k;
    double bounds[6];
    written->GetBounds(bounds);
    EXPECT_EQ(bounds[4], PlaneZ) << k;
    EXPECT_EQ(bounds[5], PlaneZ) << k;
  }
  vtkNew<vtkXMLPolyDataReader> last;
  last->SetFileName(writer->GetWrittenFileName(3));
  last->Update();
  deformable->IterateFromZeroOn();
  deformable->SetNumberOfIterations(12);
  deformable->Update();
  EXPECT_EQ(Coordinates(last->GetOutput()), Coordinates(deformable->GetOutput()));
}

// Region force over a 2-D image: the intensities come with the force field
// (vtkExternalForceField passes its input's scalars) and the result is the
// 2-D ITK filter's.
TEST(VTKDeformableContour, RegionForceIsThe2DITKFilters)
{
  const auto                image = MakeImage(TestGeometry(), { TestEllipse });
  const auto                forces = MakeForces(image);
  const auto                circle = MakeCircle(TestEllipse.center[0], TestEllipse.center[1], 8.0, 100, 0.0);
  vtkNew<vtkDeformableMesh> deformable;
  deformable->SetInputData(circle);
  deformable->SetForceImageConnection(forces->GetOutputPort());
  deformable->SetScaleFactor(0.25);
  deformable->SetElasticity(0.3);
  deformable->SetRegionWeight(0.25);
  deformable->SetNumberOfIterations(120);
  deformable->Update();
  ASSERT_EQ(deformable->GetOutput()->GetNumberOfPoints(), 100);

  auto reference = ReferenceFilter(circle, image);
  reference->SetIntensityImage(
    edm::ImageDataToImage<ContourFilterType::IntensityImageType>(image, image->GetPointData()->GetArray("Intensity")));
  reference->SetScaleFactor(0.25);
  reference->SetElasticity(0.3);
  reference->SetRegionWeight(0.25);
  reference->SetNumberOfIterations(120);
  reference->Update();
  double mean = 0.0;
  double maximum = 0.0;
  MeasureDistance(deformable->GetOutput(), TestEllipse, mean, maximum);
  std::cout << "region force from a circle of radius 8: mean " << mean << " pixel, max " << maximum << " pixel"
            << std::endl;
  EXPECT_LE(mean, 0.25);
  for (vtkIdType i = 0; i < 100; ++i)
  {
    double p[3];
    deformable->GetOutput()->GetPoint(i, p);
    ASSERT_EQ(p[0], reference->GetOutput()->GetPoints()->ElementAt(i)[0]) << i;
    ASSERT_EQ(p[1], reference->GetOutput()->GetPoints()->ElementAt(i)[1]) << i;
  }
}

// What is refused, each with a message naming the problem and an empty
// output, never a crash; and the same object works again with good input.
TEST(VTKDeformableContour, BadInputGivesAnErrorAndAnEmptyOutput)
{
  const auto image = MakeImage(TestGeometry(), { TestEllipse });
  const auto forces = MakeForces(image);
  const auto circle = MakeCircle(TestEllipse.center[0], TestEllipse.center[1], 17.0, 100, 0.0);
  const auto open = MakeOpenContour(20.0, 30.0, 50.0, 30.0, 21, 2.0, 0.0);

  vtkNew<vtkDeformableMesh> deformable;
  ErrorRecorder             errors(deformable);
  deformable->SetForceImageConnection(forces->GetOutputPort());
  deformable->SetScaleFactor(0.5);
  deformable->SetNumberOfIterations(5);
  auto expectRefused = [&](const char * what, const char * message) {
    deformable->Update();
    const std::string text = errors.Take();
    EXPECT_NE(text.find(message), std::string::npos) << what << ": " << text;
    EXPECT_EQ(deformable->GetOutput()->GetNumberOfPoints(), 0) << what;
    EXPECT_EQ(deformable->GetOutput()->GetNumberOfCells(), 0) << what;
  };

  // A 2-D contour over a 3-D image.
  vtkNew<vtkImageData> volume;
  volume->SetDimensions(72, 72, 8);
  vtkNew<vtkFloatArray> zero;
  zero->SetName("Force");
  zero->SetNumberOfComponents(3);
  zero->SetNumberOfTuples(volume->GetNumberOfPoints());
  zero->Fill(0.0);
  volume->GetPointData()->SetVectors(zero);
  deformable->SetInputData(circle);
  deformable->SetForceImageData(volume);
  expectRefused("a contour over a 3-D image", "the force image on input port 1 is 3-D");

  // Lines mixed with triangles over a 2-D image.
  vtkNew<vtkPolyData> mixed;
  mixed->DeepCopy(circle);
  vtkNew<vtkCellArray> triangles;
  const vtkIdType      triangle[3] = { 0, 30, 60 };
  triangles->InsertNextCell(3, triangle);
  mixed->SetPolys(triangles);
  deformable->SetInputData(mixed);
  deformable->SetForceImageConnection(forces->GetOutputPort());
  expectRefused("lines and a triangle", "1 polygon(s) or triangle(s)");

  // Triangles alone (a surface) over a 2-D image.
  vtkNew<vtkSphereSource> sphere;
  sphere->SetCenter(35.0, 35.0, 0.0);
  sphere->SetRadius(10.0);
  sphere->Update();
  deformable->SetInputData(sphere->GetOutput());
  expectRefused("a surface over a 2-D image", "the input must be contours");

  // The balloon on an open contour: outward is undefined.
  deformable->SetInputData(open);
  deformable->SetBalloon(0.1);
  expectRefused("balloon on an open contour", "outward is undefined for an open contour");
  deformable->SetBalloon(0.0);

  // A NaN point.
  vtkNew<vtkPolyData> withNaN;
  withNaN->DeepCopy(circle);
  withNaN->GetPoints()->SetPoint(7, std::nan(""), 30.0, 0.0);
  deformable->SetInputData(withNaN);
  expectRefused("a NaN point", "non-finite coordinate");

  // A line cell of one point.
  vtkNew<vtkPolyData> withDot;
  withDot->DeepCopy(circle);
  const vtkIdType dot[1] = { 3 };
  withDot->GetLines()->InsertNextCell(1, dot);
  deformable->SetInputData(withDot);
  expectRefused("a one-point line", "Line cell 1 has 1 point(s)");

  // Remeshing works on surfaces only.
  deformable->SetInputData(circle);
  deformable->SetRemeshingEdgeLength(1.0);
  expectRefused("remeshing a contour", "RemeshingEdgeLength");
  deformable->SetRemeshingEdgeLength(0.0);

  // A force array of 4 components.
  vtkNew<vtkImageData> fourComponents;
  fourComponents->DeepCopy(forces->GetOutput());
  vtkNew<vtkFloatArray> wide;
  wide->SetName("Wide");
  wide->SetNumberOfComponents(4);
  wide->SetNumberOfTuples(fourComponents->GetNumberOfPoints());
  wide->Fill(0.0);
  fourComponents->GetPointData()->AddArray(wide);
  deformable->SetForceImageData(fourComponents);
  deformable->SetInputArrayToProcess(0, 1, 0, vtkDataObject::FIELD_ASSOCIATION_POINTS, "Wide");
  expectRefused("a 4-component force array", "it must have 3 (or 2 over a 2-D image)");
  deformable->SetInputArrayToProcess(0, 1, 0, vtkDataObject::FIELD_ASSOCIATION_POINTS, "Force");

  // A direction matrix that tilts the image's plane.
  vtkNew<vtkImageData> tilted;
  tilted->DeepCopy(forces->GetOutput());
  tilted->SetDirectionMatrix(1.0, 0.0, 0.0, 0.0, std::cos(0.2), -std::sin(0.2), 0.0, std::sin(0.2), std::cos(0.2));
  deformable->SetForceImageData(tilted);
  expectRefused("a tilted plane", "its plane is not z = const");

  // An image flat along y.
  vtkNew<vtkImageData> row;
  row->SetDimensions(72, 1, 1);
  vtkNew<vtkFloatArray> rowForce;
  rowForce->SetName("Force");
  rowForce->SetNumberOfComponents(3);
  rowForce->SetNumberOfTuples(72);
  rowForce->Fill(0.0);
  row->GetPointData()->SetVectors(rowForce);
  deformable->SetForceImageData(row);
  expectRefused("a one-row image", "a 2-D image must be nx x ny x 1");

  // Good input again: it works, in the image's plane.
  deformable->SetForceImageConnection(forces->GetOutputPort());
  deformable->SetInputData(circle);
  deformable->Update();
  EXPECT_EQ(errors.Take(), "");
  EXPECT_EQ(deformable->GetOutput()->GetNumberOfPoints(), 100);
  EXPECT_EQ(deformable->GetCurrentIteration(), 5);
  EXPECT_EQ(deformable->GetOutput()->GetBounds()[4], PlaneZ);

  // vtkExternalForceField refuses an image flat along x or y.
  vtkNew<vtkExternalForceField> forceField;
  ErrorRecorder                 forceErrors(forceField);
  vtkNew<vtkImageData>          wall;
  wall->SetDimensions(1, 16, 16);
  wall->AllocateScalars(VTK_FLOAT, 1);
  wall->GetPointData()->GetScalars()->Fill(0.0);
  forceField->SetInputData(wall);
  forceField->Update();
  EXPECT_NE(forceErrors.Take().find("nx x ny x 1"), std::string::npos);
  EXPECT_EQ(forceField->GetOutput()->GetNumberOfPoints(), 0);
}

// A slice of a volume (extent k = 5 along z, z spacing 2, origin z 1, as
// vtkExtractVOI gives it): the contour ends on the ellipse in the slice's
// plane, z = 1 + 5 x 2 = 11.
TEST(VTKDeformableContour, ASliceOfAVolumeKeepsItsPlane)
{
  const auto           image = MakeImage(TestGeometry(), { TestEllipse });
  vtkNew<vtkImageData> slice;
  slice->SetExtent(0, 71, 0, 71, 5, 5);
  slice->SetOrigin(0.0, 0.0, 1.0);
  slice->SetSpacing(1.0, 1.0, 2.0);
  slice->GetPointData()->SetScalars(image->GetPointData()->GetScalars());
  const auto forces = MakeForces(slice);
  ASSERT_EQ(forces->GetOutput()->GetNumberOfPoints(), 72 * 72);
  const auto                circle = MakeCircle(TestEllipse.center[0], TestEllipse.center[1], 17.0, 200, 0.0);
  vtkNew<vtkDeformableMesh> deformable;
  deformable->SetInputData(circle);
  deformable->SetForceImageConnection(forces->GetOutputPort());
  deformable->SetScaleFactor(0.5);
  deformable->SetElasticity(0.3);
  deformable->SetNumberOfIterations(400);
  deformable->Update();
  ASSERT_EQ(deformable->GetOutput()->GetNumberOfPoints(), 200);
  double mean = 0.0;
  double maximum = 0.0;
  MeasureDistance(deformable->GetOutput(), TestEllipse, mean, maximum);
  EXPECT_LE(mean, 0.1);
  EXPECT_LE(maximum, 0.3);
  EXPECT_EQ(deformable->GetOutput()->GetBounds()[4], 11.0);
  EXPECT_EQ(deformable->GetOutput()->GetBounds()[5], 11.0);
}
