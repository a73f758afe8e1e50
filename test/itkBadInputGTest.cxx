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

// Bad input to the filters: non-finite and extreme images, NaN force images,
// huge sigma and steps, degenerate meshes. Each is an itk::ExceptionObject
// naming the cause, or (for finite extreme intensities) the same field as for
// ordinary ones; never a non-finite output.

#include "itkDeformableMeshFilter.h"
#include "itkEllipsoidPhantom.h"
#include "itkExternalForceImageFilter.h"
#include "itkIterativeMeshFilter.h"
#include "itkMesh.h"
#include "itkTriangleCell.h"

#include "gtest/gtest.h"

#include <chrono>
#include <cmath>
#include <limits>
#include <string>

namespace
{
using MeshType = itk::Mesh<double, 3, itk::DefaultStaticMeshTraits<double, 3, 3, double, double, double>>;
using PointType = MeshType::PointType;
using FloatImageType = itk::Image<float, 3>;
using DoubleImageType = itk::Image<double, 3>;
using ForceImageType = itk::Image<itk::CovariantVector<float, 3>, 3>;
using DeformFilterType = itk::DeformableMeshFilter<MeshType, ForceImageType>;

constexpr double NaN = std::numeric_limits<double>::quiet_NaN();
constexpr double Infinity = std::numeric_limits<double>::infinity();

/** The seed's ball in a cube of \a n voxels of 1 mm: \a inside in the ball of
 * radius n/4 at the centre, \a outside elsewhere. */
template <typename TImage>
typename TImage::Pointer
MakeBall(unsigned int n, typename TImage::PixelType inside, typename TImage::PixelType outside)
{
  itk::EllipsoidPhantom::PointType center;
  center.Fill(0.5 * (n - 1.0));
  itk::EllipsoidPhantom::VectorType radii;
  radii.Fill(0.25 * n);
  const itk::EllipsoidPhantom ball(center, radii);
  typename TImage::SizeType   size;
  size.Fill(n);
  typename TImage::SpacingType spacing(1.0);
  typename TImage::PointType   origin(0.0);
  return ball.MakeImage<TImage>(size, spacing, origin, TImage::DirectionType::GetIdentity(), inside, outside);
}

template <typename TImage>
ForceImageType::Pointer
ComputeForces(const TImage * image, double sigma, bool normalize = true)
{
  auto filter = itk::ExternalForceImageFilter<TImage, ForceImageType>::New();
  filter->SetInput(image);
  filter->SetSigma(sigma);
  filter->SetNormalizeForces(normalize);
  filter->Update();
  ForceImageType::Pointer forces = filter->GetOutput();
  forces->DisconnectPipeline();
  return forces;
}

/** The description of the ExceptionObject an update throws, or "". */
template <typename TFilter>
std::string
UpdateAndGetError(TFilter * filter)
{
  try
  {
    filter->Update();
  }
  catch (const itk::ExceptionObject & exception)
  {
    return exception.GetDescription();
  }
  return std::string();
}

bool
AllFinite(const ForceImageType * forces)
{
  const auto * f = forces->GetBufferPointer();
  for (itk::SizeValueType i = 0; i < forces->GetBufferedRegion().GetNumberOfPixels(); ++i)
  {
    for (unsigned int k = 0; k < 3; ++k)
    {
      if (!std::isfinite(f[i][k]))
      {
        return false;
      }
    }
  }
  return true;
}

/** Largest difference between two fields of the same size. */
double
LargestDifference(const ForceImageType * a, const ForceImageType * b)
{
  double       largest = 0.0;
  const auto * p = a->GetBufferPointer();
  const auto * q = b->GetBufferPointer();
  for (itk::SizeValueType i = 0; i < a->GetBufferedRegion().GetNumberOfPixels(); ++i)
  {
    largest = std::max(largest, static_cast<double>((p[i] - q[i]).GetNorm()));
  }
  return largest;
}

/** A constant force field of \a n^3 voxels of 1 mm. */
ForceImageType::Pointer
MakeConstantForces(unsigned int n, float value)
{
  auto                     image = ForceImageType::New();
  ForceImageType::SizeType size;
  size.Fill(n);
  image->SetRegions(size);
  image->Allocate();
  image->FillBuffer(ForceImageType::PixelType(value));
  return image;
}

MeshType::Pointer
MakeSphere(double centre, double radius)
{
  PointType c;
  c.Fill(centre);
  return itk::MakeSphereMesh<MeshType>(c, radius, 2);
}

/** One more step of the test filter below sets point 0 to NaN at iteration
 * FailAt: the base class must throw, naming that iteration. */
class DivergingMeshFilter : public itk::IterativeMeshFilter<MeshType>
{
public:
  ITK_DISALLOW_COPY_AND_MOVE(DivergingMeshFilter);
  using Self = DivergingMeshFilter;
  using Superclass = itk::IterativeMeshFilter<MeshType>;
  using Pointer = itk::SmartPointer<Self>;
  itkNewMacro(Self);
  itkOverrideGetNameOfClassMacro(DivergingMeshFilter);

  itk::SizeValueType FailAt{ 3 };
  itk::SizeValueType Steps{ 0 };

protected:
  DivergingMeshFilter() = default;
  void
  Iterate() override
  {
    ++Steps;
    for (auto & x : this->GetCoordinates())
    {
      x += 1.0;
    }
    if (this->GetCurrentIteration() + 1 == FailAt)
    {
      this->GetCoordinates()[1] = NaN;
    }
  }
};
} // namespace

TEST(BadInput, NonFiniteImageIsAnException)
{
  for (const float bad : { static_cast<float>(NaN), static_cast<float>(Infinity), static_cast<float>(-Infinity) })
  {
    auto                      image = MakeBall<FloatImageType>(16, 1.0f, 0.0f);
    FloatImageType::IndexType index = { { 3, 5, 7 } };
    image->SetPixel(index, bad);
    auto filter = itk::ExternalForceImageFilter<FloatImageType, ForceImageType>::New();
    filter->SetInput(image);
    EXPECT_THROW(filter->Update(), itk::ExceptionObject);
    const std::string message = UpdateAndGetError(filter.GetPointer());
    EXPECT_NE(message.find("non-finite value"), std::string::npos) << message;
    EXPECT_NE(message.find("[3, 5, 7]"), std::string::npos) << message;
  }
}

TEST(BadInput, ExtremeIntensitiesGiveTheOrdinaryNormalisedField)
{
  // The normalised field does not depend on the intensity scale: the largest
  // float, a denormal float and 1e300 as double give the field of 0/1.
  const auto reference = ComputeForces(MakeBall<FloatImageType>(24, 1.0f, 0.0f).GetPointer(), 1.5);
  const auto largest = ComputeForces(MakeBall<FloatImageType>(24, 3.4e38f, 0.0f).GetPointer(), 1.5);
  const auto negative = ComputeForces(MakeBall<FloatImageType>(24, 0.0f, -3.4e38f).GetPointer(), 1.5);
  const auto denormal = ComputeForces(MakeBall<FloatImageType>(24, 1e-40f, 0.0f).GetPointer(), 1.5);
  const auto huge = ComputeForces(MakeBall<DoubleImageType>(24, 1e300, 0.0).GetPointer(), 1.5);
  const auto tiny = ComputeForces(MakeBall<DoubleImageType>(24, 1e-300, 0.0).GetPointer(), 1.5);
  for (const auto & field : { largest, negative, denormal, huge, tiny })
  {
    ASSERT_TRUE(AllFinite(field));
    EXPECT_LT(LargestDifference(field, reference), 1e-5);
  }
}

TEST(BadInput, RawForcesBeyondTheFloatRangeAreAnException)
{
  // Raw forces of a 3.4e38 step are about 1e38 per mm^2: the field's float
  // pixels hold them; 1e300 as double cannot be held.
  const auto raw = ComputeForces(MakeBall<FloatImageType>(24, 3.4e38f, 0.0f).GetPointer(), 1.5, false);
  EXPECT_TRUE(AllFinite(raw));
  auto filter = itk::ExternalForceImageFilter<DoubleImageType, ForceImageType>::New();
  filter->SetInput(MakeBall<DoubleImageType>(24, 1e300, 0.0));
  filter->SetNormalizeForces(false);
  const std::string message = UpdateAndGetError(filter.GetPointer());
  EXPECT_NE(message.find("not finite"), std::string::npos) << message;
  EXPECT_NE(message.find("NormalizeForces"), std::string::npos) << message;
}

TEST(BadInput, SigmaBeyondTheImageIsAnExceptionAndQuick)
{
  const auto image = MakeBall<FloatImageType>(32, 1.0f, 0.0f);
  for (const double sigma : { 1e20, 1e10, 1e7, 33.0 })
  {
    const auto start = std::chrono::steady_clock::now();
    auto       filter = itk::ExternalForceImageFilter<FloatImageType, ForceImageType>::New();
    filter->SetInput(image);
    filter->SetSigma(sigma);
    const std::string message = UpdateAndGetError(filter.GetPointer());
    EXPECT_NE(message.find("exceeds the largest physical extent"), std::string::npos) << sigma << ": " << message;
    EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), 1.0);
  }
  for (const double sigma : { -1.0, NaN, Infinity })
  {
    auto filter = itk::ExternalForceImageFilter<FloatImageType, ForceImageType>::New();
    filter->SetInput(image);
    filter->SetSigma(sigma);
    EXPECT_THROW(filter->Update(), itk::ExceptionObject);
  }
}

TEST(BadInput, SigmaUpToTheExtentIsFiniteSymmetricAndQuick)
{
  // A kernel wider than the image (radius 4 sigma = 128 pixels on 32): the
  // taps beyond the ends are folded onto the border pixels, so the cost stays
  // that of 32 taps, and the field of the centred ball stays symmetric.
  const auto image = MakeBall<FloatImageType>(32, 1.0f, 0.0f);
  const auto start = std::chrono::steady_clock::now();
  const auto forces = ComputeForces(image.GetPointer(), 32.0);
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), 5.0);
  ASSERT_TRUE(AllFinite(forces));
  ForceImageType::IndexType a = { { 4, 10, 16 } };
  ForceImageType::IndexType b = { { 27, 10, 16 } }; // a mirrored in x
  EXPECT_NEAR(forces->GetPixel(a)[0], -forces->GetPixel(b)[0], 1e-5);
  EXPECT_NEAR(forces->GetPixel(a)[1], forces->GetPixel(b)[1], 1e-5);

  // Folding is exact: sigma 4 (radius 16 taps) on a 16-voxel axis is the same
  // field whether the taps from 16 on are folded or not. Against the image
  // padded with its border pixels, where no tap reaches beyond the end.
  const auto               small = MakeBall<FloatImageType>(16, 1.0f, 0.0f);
  const auto               folded = ComputeForces(small.GetPointer(), 4.0);
  auto                     padded = FloatImageType::New();
  FloatImageType::SizeType paddedSize = { { 64, 64, 64 } };
  padded->SetRegions(paddedSize);
  padded->Allocate();
  for (unsigned int z = 0; z < 64; ++z)
  {
    for (unsigned int y = 0; y < 64; ++y)
    {
      for (unsigned int x = 0; x < 64; ++x)
      {
        auto clamp = [](unsigned int v) {
          return static_cast<itk::IndexValueType>(std::min(15u, v > 24 ? v - 24 : 0u));
        };
        FloatImageType::IndexType to = { { x, y, z } };
        FloatImageType::IndexType from = { { clamp(x), clamp(y), clamp(z) } };
        padded->SetPixel(to, small->GetPixel(from));
      }
    }
  }
  auto filter = itk::ExternalForceImageFilter<FloatImageType, ForceImageType>::New();
  filter->SetInput(padded);
  filter->SetSigma(4.0);
  filter->SetNormalizeForces(false);
  filter->Update();
  auto   unnormalised = ComputeForces(small.GetPointer(), 4.0, false);
  double largest = 0.0;
  for (unsigned int z = 2; z < 14; ++z)
  {
    for (unsigned int y = 2; y < 14; ++y)
    {
      for (unsigned int x = 2; x < 14; ++x)
      {
        ForceImageType::IndexType i = { { x, y, z } };
        ForceImageType::IndexType j = { { x + 24, y + 24, z + 24 } };
        largest = std::max(
          largest, static_cast<double>((unnormalised->GetPixel(i) - filter->GetOutput()->GetPixel(j)).GetNorm()));
      }
    }
  }
  EXPECT_LT(largest, 1e-6);
  EXPECT_TRUE(AllFinite(folded));
}

TEST(BadInput, NonFiniteForceImageIsAnException)
{
  for (const float bad : { static_cast<float>(NaN), static_cast<float>(Infinity) })
  {
    auto                      forces = MakeConstantForces(16, 0.0f);
    ForceImageType::IndexType index = { { 1, 2, 3 } };
    ForceImageType::PixelType pixel(0.0f);
    pixel[1] = bad;
    forces->SetPixel(index, pixel);
    auto filter = DeformFilterType::New();
    filter->SetInput(MakeSphere(8.0, 3.0));
    filter->SetForceImage(forces);
    filter->SetNumberOfIterations(5);
    EXPECT_THROW(filter->Update(), itk::ExceptionObject);
    const std::string message = UpdateAndGetError(filter.GetPointer());
    EXPECT_NE(message.find("non-finite value"), std::string::npos) << message;
    EXPECT_NE(message.find("[1, 2, 3]"), std::string::npos) << message;
  }
}

TEST(BadInput, StepsLargerThanTheImageAreAnException)
{
  const auto forces = MakeConstantForces(16, 0.5f);
  const auto sphere = MakeSphere(8.0, 3.0);
  struct Case
  {
    double scale;
    double balloon;
    double maximumStep;
    bool   fails;
  };
  for (const Case & c : { Case{ 1e200, 0.0, 0.0, true },
                          Case{ 0.1, 1e200, 0.0, true },
                          Case{ -1e200, 0.0, 0.0, true },
                          Case{ 1e200, 1e200, 0.5, false },
                          Case{ 0.1, 0.1, 0.0, false } })
  {
    auto filter = DeformFilterType::New();
    filter->SetInput(sphere);
    filter->SetForceImage(forces);
    filter->SetScaleFactor(c.scale);
    filter->SetBalloon(c.balloon);
    filter->SetMaximumStepLength(c.maximumStep);
    filter->SetNumberOfIterations(3);
    const std::string message = UpdateAndGetError(filter.GetPointer());
    if (c.fails)
    {
      EXPECT_NE(message.find("more than the diagonal of the force image"), std::string::npos) << message;
    }
    else
    {
      EXPECT_EQ(message, "");
      for (auto it = filter->GetOutput()->GetPoints()->Begin(); it != filter->GetOutput()->GetPoints()->End(); ++it)
      {
        for (unsigned int k = 0; k < 3; ++k)
        {
          ASSERT_TRUE(std::isfinite(it.Value()[k]));
        }
      }
    }
  }
}

TEST(BadInput, DivergedStepIsAnExceptionNamingTheIteration)
{
  auto mesh = MakeSphere(0.0, 1.0);
  auto filter = DivergingMeshFilter::New();
  filter->SetInput(mesh);
  filter->SetNumberOfIterations(10);
  filter->FailAt = 4;
  const std::string message = UpdateAndGetError(filter.GetPointer());
  EXPECT_NE(message.find("Point #0 has a non-finite coordinate"), std::string::npos) << message;
  EXPECT_NE(message.find("after iteration 10"), std::string::npos) << message;

  // With an observer, the update stops at the iteration that diverged, and the
  // observer never sees its mesh.
  filter->Steps = 0;
  unsigned int seen = 0;
  bool         finite = true;
  filter->AddObserver(itk::IterationEvent(), [&](const itk::EventObject &) {
    ++seen;
    finite = finite && std::isfinite(filter->GetOutput()->GetPoint(0)[1]);
  });
  filter->Modified();
  const std::string observed = UpdateAndGetError(filter.GetPointer());
  EXPECT_NE(observed.find("after iteration 4 (this update ran iterations 1 to 4)"), std::string::npos) << observed;
  EXPECT_EQ(seen, 3u);
  EXPECT_TRUE(finite);

  // The next update starts again from the input.
  filter->FailAt = 100;
  filter->IterateFromZeroOff();
  filter->SetNumberOfIterations(2);
  filter->Steps = 0;
  filter->Modified();
  EXPECT_EQ(UpdateAndGetError(filter.GetPointer()), "");
  EXPECT_EQ(filter->Steps, 2u);
  EXPECT_DOUBLE_EQ(filter->GetOutput()->GetPoint(0)[0], mesh->GetPoint(0)[0] + 2.0);
}

TEST(BadInput, DegenerateMeshesAreExceptions)
{
  const auto forces = MakeConstantForces(16, 0.1f);
  const auto sphere = MakeSphere(8.0, 3.0);
  auto       run = [&](MeshType * mesh, double balloon) {
    auto filter = DeformFilterType::New();
    filter->SetInput(mesh);
    filter->SetForceImage(forces);
    filter->SetBalloon(balloon);
    filter->SetElasticity(0.3);
    filter->SetRigidity(0.1);
    filter->SetNumberOfIterations(5);
    return UpdateAndGetError(filter.GetPointer());
  };

  // No point at all.
  auto empty = MeshType::New();
  EXPECT_NE(run(empty, 0.0).find("empty"), std::string::npos);

  // A cell naming a point the mesh does not have.
  auto dangling = MeshType::New();
  dangling->SetPoints(sphere->GetPoints());
  using CellAutoPointer = MeshType::CellType::CellAutoPointer;
  using TriangleType = itk::TriangleCell<MeshType::CellType>;
  CellAutoPointer cell;
  cell.TakeOwnership(new TriangleType);
  cell->SetPointId(0, 0);
  cell->SetPointId(1, 1);
  cell->SetPointId(2, 5000);
  dangling->SetCell(0, cell);
  EXPECT_NE(run(dangling, 0.0).find("refers to point 5000"), std::string::npos) << run(dangling, 0.0);

  // A NaN and an infinite coordinate.
  for (const double bad : { NaN, Infinity })
  {
    auto broken = MeshType::New();
    broken->Graft(sphere);
    auto points = MeshType::PointsContainer::New();
    for (auto it = sphere->GetPoints()->Begin(); it != sphere->GetPoints()->End(); ++it)
    {
      points->InsertElement(it.Index(), it.Value());
    }
    PointType p = points->ElementAt(7);
    p[0] = bad;
    points->SetElement(7, p);
    broken->SetPoints(points);
    EXPECT_NE(run(broken, 0.0).find("non-finite coordinate"), std::string::npos);
  }

  // Coordinates so large that the normals overflow (1e200 squared): the
  // balloon's first step is non-finite, which is an exception, not a mesh.
  auto far = MeshType::New();
  far->Graft(sphere);
  auto farPoints = MeshType::PointsContainer::New();
  for (auto it = sphere->GetPoints()->Begin(); it != sphere->GetPoints()->End(); ++it)
  {
    PointType p = it.Value();
    for (unsigned int k = 0; k < 3; ++k)
    {
      p[k] = (p[k] - 8.0) * 1e200;
    }
    farPoints->InsertElement(it.Index(), p);
  }
  far->SetPoints(farPoints);
  const std::string farMessage = run(far, 0.1);
  EXPECT_NE(farMessage.find("non-finite coordinate"), std::string::npos) << farMessage;
  EXPECT_NE(farMessage.find("after iteration 5"), std::string::npos) << farMessage;
}
