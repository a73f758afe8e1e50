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

#include "itkBrownianMeshFilter.h"
#include "itkMesh.h"

#include "gtest/gtest.h"

#include <cmath>
#include <limits>
#include <sstream>

namespace
{
using MeshType = itk::Mesh<double, 3>;
using PointType = MeshType::PointType;

/** Points on a 7 x 11 x n lattice of unit spacing, without cells. */
MeshType::Pointer
MakePointCloud(unsigned int numberOfPoints)
{
  auto mesh = MeshType::New();
  mesh->GetPoints()->Reserve(numberOfPoints);
  for (unsigned int i = 0; i < numberOfPoints; ++i)
  {
    PointType p;
    p[0] = i % 7;
    p[1] = (i / 7) % 11;
    p[2] = i / 77;
    mesh->SetPoint(i, p);
  }
  return mesh;
}
} // namespace

TEST(BrownianMeshFilter, SameSeedSameOutputAndThreadIndependent)
{
  const auto mesh = MakePointCloud(10000);
  auto       run = [&](uint64_t seed, unsigned int workUnits, unsigned int iterations) {
    using FilterType = itk::BrownianMeshFilter<MeshType>;
    auto filter = FilterType::New();
    filter->SetInput(mesh);
    filter->SetSeed(seed);
    filter->SetStepLength(0.5);
    filter->SetNumberOfWorkUnits(workUnits);
    filter->SetNumberOfIterations(iterations);
    filter->Update();
    MeshType::Pointer output = filter->GetOutput();
    output->DisconnectPipeline();
    return output;
  };
  const auto   a = run(42, 1, 3);
  const auto   b = run(42, 2, 3);
  const auto   c = run(43, 2, 3);
  unsigned int different = 0;
  for (MeshType::PointIdentifier i = 0; i < mesh->GetNumberOfPoints(); ++i)
  {
    for (unsigned int d = 0; d < 3; ++d)
    {
      EXPECT_EQ(a->GetPoint(i)[d], b->GetPoint(i)[d]);
      different += a->GetPoint(i)[d] != c->GetPoint(i)[d];
    }
  }
  EXPECT_EQ(different, 3u * mesh->GetNumberOfPoints()) << "another seed gives another walk";
}

TEST(BrownianMeshFilter, ContinuationEqualsRunningAtOnce)
{
  const auto mesh = MakePointCloud(500);
  using FilterType = itk::BrownianMeshFilter<MeshType>;
  auto once = FilterType::New();
  once->SetInput(mesh);
  once->SetNumberOfIterations(6);
  once->Update();
  auto stepwise = FilterType::New();
  stepwise->SetInput(mesh);
  stepwise->IterateFromZeroOff();
  for (unsigned int n = 1; n <= 6; ++n)
  {
    stepwise->SetNumberOfIterations(n);
    stepwise->Update();
  }
  for (MeshType::PointIdentifier i = 0; i < mesh->GetNumberOfPoints(); ++i)
  {
    for (unsigned int d = 0; d < 3; ++d)
    {
      EXPECT_EQ(once->GetOutput()->GetPoint(i)[d], stepwise->GetOutput()->GetPoint(i)[d]);
    }
  }
}

TEST(BrownianMeshFilter, DisplacementStatisticsMatchTheStepLength)
{
  // n points, 4 iterations of step length L: each displacement component is
  // N(0, 4 L^2 / 3), the squared length has mean 4 L^2 and variance
  // 2 * 3 * (4 L^2 / 3)^2.
  constexpr unsigned int n = 60000;
  constexpr double       stepLength = 2.0;
  constexpr unsigned int iterations = 4;
  const auto             mesh = MakePointCloud(n);
  using FilterType = itk::BrownianMeshFilter<MeshType>;
  auto filter = FilterType::New();
  filter->SetInput(mesh);
  filter->SetStepLength(stepLength);
  filter->SetSeed(7);
  filter->SetNumberOfIterations(iterations);
  filter->Update();

  const double componentVariance = iterations * stepLength * stepLength / 3.0;
  double       sum[3] = { 0, 0, 0 };
  double       sumSquares[3] = { 0, 0, 0 };
  double       sumLengthSquared = 0.0;
  for (MeshType::PointIdentifier i = 0; i < n; ++i)
  {
    const auto d = filter->GetOutput()->GetPoint(i) - mesh->GetPoint(i);
    for (unsigned int k = 0; k < 3; ++k)
    {
      sum[k] += d[k];
      sumSquares[k] += d[k] * d[k];
    }
    sumLengthSquared += d.GetSquaredNorm();
  }
  for (unsigned int k = 0; k < 3; ++k)
  {
    // Mean within 5 standard errors of 0; variance within 5 standard errors.
    EXPECT_NEAR(sum[k] / n, 0.0, 5.0 * std::sqrt(componentVariance / n));
    EXPECT_NEAR(sumSquares[k] / n, componentVariance, 5.0 * componentVariance * std::sqrt(2.0 / n));
  }
  const double meanSquaredLength = iterations * stepLength * stepLength;
  EXPECT_NEAR(sumLengthSquared / n, meanSquaredLength, 5.0 * std::sqrt(6.0 / n) * componentVariance);
}

TEST(BrownianMeshFilter, RejectsInvalidStepLength)
{
  using FilterType = itk::BrownianMeshFilter<MeshType>;
  auto filter = FilterType::New();
  filter->SetInput(MakePointCloud(4));
  filter->SetNumberOfIterations(1);
  for (const double bad : { -1.0, std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::infinity() })
  {
    filter->SetStepLength(bad);
    try
    {
      filter->Update();
      FAIL() << "StepLength " << bad << " must throw";
    }
    catch (const itk::ExceptionObject & e)
    {
      EXPECT_NE(std::string(e.GetDescription()).find("StepLength"), std::string::npos) << e.GetDescription();
    }
  }
  filter->SetStepLength(0.0);
  EXPECT_NO_THROW(filter->Update());
  std::ostringstream os;
  filter->Print(os);
  EXPECT_NE(os.str().find("StepLength: 0"), std::string::npos);
  EXPECT_NE(os.str().find("Seed: 0"), std::string::npos);
}
