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

// The iteration contract of IterativeMeshFilter (checked on a filter whose
// step is an exact translation, so every answer is known), and the Brownian
// random walk.

#include "itkCommand.h"
#include "itkIterativeMeshFilter.h"
#include "itkMesh.h"
#include "itkTriangleCell.h"

#include "gtest/gtest.h"

#include <cmath>
#include <limits>

namespace
{
using MeshType = itk::Mesh<double, 3>;
using PointType = MeshType::PointType;

/** Moves every point by (1, 0, 0) per iteration and counts its steps and resets. */
class TranslationFilter : public itk::IterativeMeshFilter<MeshType>
{
public:
  ITK_DISALLOW_COPY_AND_MOVE(TranslationFilter);
  using Self = TranslationFilter;
  using Superclass = itk::IterativeMeshFilter<MeshType>;
  using Pointer = itk::SmartPointer<Self>;
  itkNewMacro(Self);
  itkOverrideGetNameOfClassMacro(TranslationFilter);

  unsigned int m_Steps{ 0 };
  unsigned int m_Resets{ 0 };

protected:
  TranslationFilter() = default;
  ~TranslationFilter() override = default;
  void
  Reset() override
  {
    ++m_Resets;
  }
  void
  Iterate() override
  {
    ++m_Steps;
    std::vector<double> & x = this->GetCoordinates();
    for (size_t i = 0; i < x.size(); i += 3)
    {
      x[i] += 1.0;
    }
  }
};

/** A tetrahedron's surface: 4 points, 4 triangles, point and cell data. */
MeshType::Pointer
MakeTetrahedron()
{
  auto         mesh = MeshType::New();
  const double coordinates[4][3] = { { 0, 0, 0 }, { 1, 0, 0 }, { 0, 1, 0 }, { 0, 0, 1 } };
  for (unsigned int i = 0; i < 4; ++i)
  {
    mesh->SetPoint(i, PointType(coordinates[i]));
    mesh->SetPointData(i, 10.0 + i);
  }
  const unsigned int triangles[4][3] = { { 0, 2, 1 }, { 0, 1, 3 }, { 0, 3, 2 }, { 1, 2, 3 } };
  using TriangleType = itk::TriangleCell<MeshType::CellType>;
  for (unsigned int c = 0; c < 4; ++c)
  {
    MeshType::CellAutoPointer cell;
    cell.TakeOwnership(new TriangleType);
    for (unsigned int k = 0; k < 3; ++k)
    {
      cell->SetPointId(k, triangles[c][k]);
    }
    mesh->SetCell(c, cell);
    mesh->SetCellData(c, 100.0 + c);
  }
  return mesh;
}

/** Checks that output point i is input point i + (shift, 0, 0), exactly. */
void
ExpectShifted(const MeshType * input, const MeshType * output, double shift)
{
  ASSERT_EQ(input->GetNumberOfPoints(), output->GetNumberOfPoints());
  for (MeshType::PointIdentifier i = 0; i < input->GetNumberOfPoints(); ++i)
  {
    const PointType p = input->GetPoint(i);
    const PointType q = output->GetPoint(i);
    EXPECT_EQ(q[0], p[0] + shift) << "point " << i;
    EXPECT_EQ(q[1], p[1]) << "point " << i;
    EXPECT_EQ(q[2], p[2]) << "point " << i;
  }
}

} // namespace

TEST(IterativeMeshFilter, ZeroIterationsGivesTheInputBack)
{
  const auto mesh = MakeTetrahedron();
  auto       filter = TranslationFilter::New();
  filter->SetInput(mesh);
  EXPECT_EQ(filter->GetNumberOfIterations(), 0u);
  EXPECT_TRUE(filter->GetIterateFromZero());
  filter->Update();
  EXPECT_EQ(filter->GetCurrentIteration(), 0u);
  EXPECT_EQ(filter->m_Steps, 0u);
  ExpectShifted(mesh, filter->GetOutput(), 0.0);
}

TEST(IterativeMeshFilter, IteratesFromZeroByDefault)
{
  const auto mesh = MakeTetrahedron();
  auto       filter = TranslationFilter::New();
  filter->SetInput(mesh);
  filter->SetNumberOfIterations(5);
  filter->Update();
  EXPECT_EQ(filter->GetCurrentIteration(), 5u);
  EXPECT_EQ(filter->m_Steps, 5u);
  ExpectShifted(mesh, filter->GetOutput(), 5.0);

  // Raising the count restarts from the input and runs all iterations.
  filter->SetNumberOfIterations(6);
  filter->Update();
  EXPECT_EQ(filter->GetCurrentIteration(), 6u);
  EXPECT_EQ(filter->m_Steps, 11u);
  EXPECT_EQ(filter->m_Resets, 2u);
  ExpectShifted(mesh, filter->GetOutput(), 6.0);
}

TEST(IterativeMeshFilter, ContinuesWithOneMoreStepWhenNotIteratingFromZero)
{
  const auto mesh = MakeTetrahedron();
  auto       filter = TranslationFilter::New();
  filter->SetInput(mesh);
  filter->IterateFromZeroOff();
  filter->SetNumberOfIterations(3);
  filter->Update();
  EXPECT_EQ(filter->m_Steps, 3u);
  for (unsigned int n = 4; n <= 8; ++n)
  {
    filter->SetNumberOfIterations(n);
    filter->Update();
    EXPECT_EQ(filter->m_Steps, n) << "exactly one more step per increment";
    EXPECT_EQ(filter->GetCurrentIteration(), n);
    ExpectShifted(mesh, filter->GetOutput(), static_cast<double>(n));
  }
  EXPECT_EQ(filter->m_Resets, 1u);

  // Below the current iteration: restart from the input.
  filter->SetNumberOfIterations(2);
  filter->Update();
  EXPECT_EQ(filter->m_Resets, 2u);
  EXPECT_EQ(filter->m_Steps, 10u);
  ExpectShifted(mesh, filter->GetOutput(), 2.0);

  // Zero: the input again, then continuation restarts from it.
  filter->SetNumberOfIterations(0);
  filter->Update();
  EXPECT_EQ(filter->GetCurrentIteration(), 0u);
  ExpectShifted(mesh, filter->GetOutput(), 0.0);
  filter->SetNumberOfIterations(1);
  filter->Update();
  EXPECT_EQ(filter->m_Steps, 11u);
  ExpectShifted(mesh, filter->GetOutput(), 1.0);
}

TEST(IterativeMeshFilter, RestartsWhenTheInputChanges)
{
  auto mesh = MakeTetrahedron();
  auto filter = TranslationFilter::New();
  filter->SetInput(mesh);
  filter->IterateFromZeroOff();
  filter->SetNumberOfIterations(3);
  filter->Update();
  mesh->SetPoint(0, PointType(5.0));
  mesh->Modified();
  filter->Update();
  EXPECT_EQ(filter->m_Resets, 2u);
  EXPECT_EQ(filter->GetOutput()->GetPoint(0)[0], 8.0);
}

TEST(IterativeMeshFilter, NeverModifiesTheInput)
{
  const auto mesh = MakeTetrahedron();
  const auto reference = MakeTetrahedron();
  auto       filter = TranslationFilter::New();
  filter->SetInput(mesh);
  filter->IterateFromZeroOff();
  for (unsigned int n = 1; n <= 3; ++n)
  {
    filter->SetNumberOfIterations(n);
    filter->Update();
  }
  ExpectShifted(reference, mesh, 0.0);
  EXPECT_NE(filter->GetOutput()->GetPoints(), mesh->GetPoints());
}

TEST(IterativeMeshFilter, CopiesCellsCellDataAndPointData)
{
  const auto mesh = MakeTetrahedron();
  auto       filter = TranslationFilter::New();
  filter->SetInput(mesh);
  filter->SetNumberOfIterations(2);
  filter->Update();
  const MeshType * output = filter->GetOutput();
  ASSERT_EQ(output->GetNumberOfCells(), 4u);
  for (MeshType::CellIdentifier c = 0; c < 4; ++c)
  {
    MeshType::CellAutoPointer in;
    MeshType::CellAutoPointer out;
    ASSERT_TRUE(mesh->GetCell(c, in));
    ASSERT_TRUE(output->GetCell(c, out));
    ASSERT_EQ(out->GetNumberOfPoints(), 3u);
    for (unsigned int k = 0; k < 3; ++k)
    {
      EXPECT_EQ(out->PointIdsBegin()[k], in->PointIdsBegin()[k]);
    }
    double value = 0.0;
    ASSERT_TRUE(output->GetCellData(c, &value));
    EXPECT_EQ(value, 100.0 + c);
  }
  for (MeshType::PointIdentifier i = 0; i < 4; ++i)
  {
    double value = 0.0;
    ASSERT_TRUE(output->GetPointData(i, &value));
    EXPECT_EQ(value, 10.0 + i);
  }
}

TEST(IterativeMeshFilter, FiresOneIterationEventPerStepWithTheCurrentMesh)
{
  const auto mesh = MakeTetrahedron();
  auto       filter = TranslationFilter::New();
  filter->SetInput(mesh);
  filter->SetNumberOfIterations(4);
  std::vector<double> seen;
  std::vector<double> progress;
  auto                observer = [&](const itk::EventObject &) { seen.push_back(filter->GetOutput()->GetPoint(1)[0]); };
  auto                progressObserver = [&](const itk::EventObject &) { progress.push_back(filter->GetProgress()); };
  filter->AddObserver(itk::IterationEvent(), observer);
  filter->AddObserver(itk::ProgressEvent(), progressObserver);
  filter->Update();
  ASSERT_EQ(seen.size(), 4u);
  for (unsigned int k = 0; k < 4; ++k)
  {
    EXPECT_EQ(seen[k], 1.0 + (k + 1)) << "the observer sees the mesh of iteration " << k + 1;
  }
  ASSERT_FALSE(progress.empty());
  EXPECT_FLOAT_EQ(progress.back(), 1.0f);

  // Continuing by one step fires exactly one more event.
  seen.clear();
  filter->IterateFromZeroOff();
  filter->SetNumberOfIterations(5);
  filter->Update();
  ASSERT_EQ(seen.size(), 1u);
  EXPECT_EQ(seen[0], 6.0);
}

TEST(IterativeMeshFilter, AbortStopsCleanlyBetweenSteps)
{
  const auto mesh = MakeTetrahedron();
  auto       filter = TranslationFilter::New();
  filter->SetInput(mesh);
  filter->SetNumberOfIterations(10);
  filter->IterateFromZeroOff();
  unsigned int events = 0;
  auto         observer = [&](const itk::EventObject &) {
    if (++events == 3)
    {
      filter->AbortGenerateDataOn();
    }
  };
  const unsigned long tag = filter->AddObserver(itk::IterationEvent(), observer);
  filter->Update();
  EXPECT_EQ(filter->GetCurrentIteration(), 3u);
  EXPECT_EQ(filter->m_Steps, 3u);
  ExpectShifted(mesh, filter->GetOutput(), 3.0);

  // Resuming continues from iteration 3.
  filter->RemoveObserver(tag);
  filter->AbortGenerateDataOff();
  filter->Modified();
  filter->Update();
  EXPECT_EQ(filter->GetCurrentIteration(), 10u);
  EXPECT_EQ(filter->m_Steps, 10u);
  ExpectShifted(mesh, filter->GetOutput(), 10.0);
}

TEST(IterativeMeshFilter, RejectsMissingEmptyOrNonFiniteInput)
{
  auto filter = TranslationFilter::New();
  filter->SetNumberOfIterations(1);
  try
  {
    filter->Update();
    FAIL() << "no input must throw";
  }
  catch (const itk::ExceptionObject & e)
  {
    EXPECT_NE(std::string(e.GetDescription()).find("No input mesh"), std::string::npos) << e.GetDescription();
  }

  filter->SetInput(MeshType::New());
  try
  {
    filter->Update();
    FAIL() << "an empty mesh must throw";
  }
  catch (const itk::ExceptionObject & e)
  {
    EXPECT_NE(std::string(e.GetDescription()).find("empty"), std::string::npos) << e.GetDescription();
  }

  auto      mesh = MakeTetrahedron();
  PointType bad = mesh->GetPoint(2);
  bad[1] = std::numeric_limits<double>::quiet_NaN();
  mesh->SetPoint(2, bad);
  filter->SetInput(mesh);
  try
  {
    filter->Update();
    FAIL() << "a NaN coordinate must throw";
  }
  catch (const itk::ExceptionObject & e)
  {
    EXPECT_NE(std::string(e.GetDescription()).find("non-finite"), std::string::npos) << e.GetDescription();
  }
}

TEST(IterativeMeshFilter, PrintsEveryMember)
{
  // After an update of 7 iterations on the tetrahedron (4 points, 4 cells).
  auto filter = TranslationFilter::New();
  filter->SetInput(MakeTetrahedron());
  filter->SetNumberOfIterations(7);
  filter->Update();
  std::ostringstream os;
  filter->Print(os);
  for (const char * member : { "NumberOfIterations: 7",
                               "CurrentIteration: 7",
                               "IterateFromZero: On",
                               "Cached: true",
                               "CachedInputTime: ",
                               "OutputCells: 4 shared cells",
                               "OutputPoints: 4 reusable points",
                               "Coordinates: 4 cached points",
                               "OutputPointsFinite: true",
                               "NumberOfInputPoints: 4",
                               "TopologyChanged: false",
                               "OutputPointIdentifiers: cached order" })
  {
    EXPECT_NE(os.str().find(member), std::string::npos) << member << " in\n" << os.str();
  }
}
