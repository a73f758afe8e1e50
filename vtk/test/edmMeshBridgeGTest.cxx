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

// Round trips between itk::Mesh and vtkPolyData, and between itk::Image and
// vtkImageData: points, cells and arrays must come back exactly.

#include "edmMeshBridge.h"

#include "itkCovariantVector.h"
#include "itkDefaultDynamicMeshTraits.h"
#include "itkImageRegionIteratorWithIndex.h"
#include "itkQuadrilateralCell.h"
#include "itkTetrahedronCell.h"
#include "itkVariableLengthVector.h"
#include "itkVector.h"

#include "vtkCellArray.h"
#include "vtkDoubleArray.h"
#include "vtkFloatArray.h"
#include "vtkIdList.h"
#include "vtkIntArray.h"
#include "vtkNew.h"

#include "gtest/gtest.h"

#include <vector>

namespace
{
// Double coordinates, so that double VTK points come back exactly.
using MeshType = edm::PolyDataMeshType;
using CellType = MeshType::CellType;
using CellAutoPointer = CellType::CellAutoPointer;

template <typename TMesh, typename TCell>
void
AddCell(TMesh * mesh, std::vector<typename TMesh::PointIdentifier> ids)
{
  typename TMesh::CellType::CellAutoPointer cell;
  cell.TakeOwnership(new TCell);
  cell->SetPointIds(ids.data(), ids.data() + ids.size());
  mesh->SetCell(mesh->GetNumberOfCells(), cell);
}

/** Eight points; a vertex, a line, a polyline, a triangle, a polygon and a
 * second triangle, in VTK's cell order (verts, lines, polys). */
template <typename TMesh>
typename TMesh::Pointer
MakeMixedMesh()
{
  using TCell = typename TMesh::CellType;
  auto         mesh = TMesh::New();
  const double coordinates[8][3] = { { 0.0, 0.0, 0.0 }, { 1.0, 0.0, 0.0 },   { 1.0, 1.0, 0.0 }, { 0.0, 1.0, 0.0 },
                                     { 0.5, 0.5, 1.0 }, { -1.25, 2.5, 3.0 }, { 0.1, 0.2, 0.3 }, { 1e-7, -3e5, 42.0 } };
  for (unsigned int i = 0; i < 8; ++i)
  {
    typename TMesh::PointType p;
    for (unsigned int d = 0; d < 3; ++d)
    {
      p[d] = coordinates[i][d];
    }
    mesh->SetPoint(i, p);
  }
  AddCell<TMesh, itk::VertexCell<TCell>>(mesh, { 7 });
  AddCell<TMesh, itk::LineCell<TCell>>(mesh, { 5, 6 });
  AddCell<TMesh, edm::PolyLineCell<TCell>>(mesh, { 0, 6, 5, 7 });
  AddCell<TMesh, itk::TriangleCell<TCell>>(mesh, { 0, 1, 4 });
  AddCell<TMesh, itk::PolygonCell<TCell>>(mesh, { 0, 1, 2, 3, 4 });
  AddCell<TMesh, itk::TriangleCell<TCell>>(mesh, { 2, 3, 4 });
  return mesh;
}

template <typename TMesh>
void
ExpectSameCells(const TMesh * expected, const TMesh * actual)
{
  ASSERT_EQ(expected->GetNumberOfCells(), actual->GetNumberOfCells());
  for (typename TMesh::CellIdentifier c = 0; c < expected->GetNumberOfCells(); ++c)
  {
    typename TMesh::CellAutoPointer a;
    typename TMesh::CellAutoPointer b;
    ASSERT_TRUE(expected->GetCell(c, a));
    ASSERT_TRUE(actual->GetCell(c, b));
    EXPECT_EQ(a->GetType(), b->GetType()) << "cell " << c;
    EXPECT_EQ(a->GetDimension(), b->GetDimension()) << "cell " << c;
    ASSERT_EQ(a->GetNumberOfPoints(), b->GetNumberOfPoints()) << "cell " << c;
    EXPECT_TRUE(std::equal(a->PointIdsBegin(), a->PointIdsEnd(), b->PointIdsBegin())) << "cell " << c;
  }
}

template <typename TMesh>
void
ExpectSamePoints(const TMesh * expected, const TMesh * actual)
{
  ASSERT_EQ(expected->GetNumberOfPoints(), actual->GetNumberOfPoints());
  for (typename TMesh::PointIdentifier i = 0; i < expected->GetNumberOfPoints(); ++i)
  {
    EXPECT_EQ(expected->GetPoint(i), actual->GetPoint(i)) << "point " << i;
  }
}

void
ExpectSameCellArray(vtkCellArray * expected, vtkCellArray * actual)
{
  ASSERT_NE(expected, nullptr);
  ASSERT_NE(actual, nullptr);
  ASSERT_EQ(expected->GetNumberOfCells(), actual->GetNumberOfCells());
  vtkNew<vtkIdList> a;
  vtkNew<vtkIdList> b;
  for (vtkIdType c = 0; c < expected->GetNumberOfCells(); ++c)
  {
    expected->GetCellAtId(c, a);
    actual->GetCellAtId(c, b);
    ASSERT_EQ(a->GetNumberOfIds(), b->GetNumberOfIds()) << "cell " << c;
    for (vtkIdType k = 0; k < a->GetNumberOfIds(); ++k)
    {
      EXPECT_EQ(a->GetId(k), b->GetId(k)) << "cell " << c << " point " << k;
    }
  }
}

void
ExpectSameArray(vtkDataArray * expected, vtkDataArray * actual)
{
  ASSERT_NE(expected, nullptr);
  ASSERT_NE(actual, nullptr);
  EXPECT_STREQ(expected->GetName(), actual->GetName());
  EXPECT_EQ(expected->GetDataType(), actual->GetDataType());
  ASSERT_EQ(expected->GetNumberOfComponents(), actual->GetNumberOfComponents());
  ASSERT_EQ(expected->GetNumberOfTuples(), actual->GetNumberOfTuples());
  for (vtkIdType i = 0; i < expected->GetNumberOfTuples(); ++i)
  {
    for (int c = 0; c < expected->GetNumberOfComponents(); ++c)
    {
      EXPECT_EQ(expected->GetComponent(i, c), actual->GetComponent(i, c)) << "tuple " << i << " component " << c;
    }
  }
}
} // namespace

TEST(MeshBridge, ITKToVTKMapsEveryCellKind)
{
  auto mesh = MakeMixedMesh<MeshType>();
  auto polyData = edm::MeshToPolyData(mesh.GetPointer());
  ASSERT_EQ(polyData->GetNumberOfPoints(), 8);
  EXPECT_EQ(polyData->GetPoints()->GetDataType(), VTK_DOUBLE);
  EXPECT_EQ(polyData->GetNumberOfVerts(), 1);
  EXPECT_EQ(polyData->GetNumberOfLines(), 2);
  EXPECT_EQ(polyData->GetNumberOfPolys(), 3);
  EXPECT_EQ(polyData->GetNumberOfStrips(), 0);
  EXPECT_EQ(polyData->GetCellType(0), VTK_VERTEX);
  EXPECT_EQ(polyData->GetCellType(1), VTK_LINE);
  EXPECT_EQ(polyData->GetCellType(2), VTK_POLY_LINE);
  EXPECT_EQ(polyData->GetCellType(3), VTK_TRIANGLE);
  EXPECT_EQ(polyData->GetCellType(4), VTK_POLYGON);
  double p[3];
  polyData->GetPoint(7, p);
  EXPECT_EQ(p[0], 1e-7);
  EXPECT_EQ(p[1], -3e5);
  EXPECT_EQ(p[2], 42.0);

  // itk::Mesh<double, 3> has float coordinates: float VTK points.
  using FloatMeshType = itk::Mesh<double, 3>;
  auto floatMesh = MakeMixedMesh<FloatMeshType>();
  auto floatPolyData = edm::MeshToPolyData(floatMesh.GetPointer());
  EXPECT_EQ(floatPolyData->GetPoints()->GetDataType(), VTK_FLOAT);
  floatPolyData->GetPoint(7, p);
  EXPECT_EQ(p[0], static_cast<double>(1e-7f));
  auto floatBack = edm::PolyDataToMesh<FloatMeshType>(floatPolyData);
  ExpectSamePoints(floatMesh.GetPointer(), floatBack.GetPointer());
  ExpectSameCells(floatMesh.GetPointer(), floatBack.GetPointer());
}

TEST(MeshBridge, ITKToVTKToITKIsExactWithScalarData)
{
  auto mesh = MakeMixedMesh<MeshType>();
  for (unsigned int i = 0; i < 8; ++i)
  {
    mesh->SetPointData(i, 0.1 * i - 3.0);
  }
  for (unsigned int c = 0; c < mesh->GetNumberOfCells(); ++c)
  {
    mesh->SetCellData(c, 1.0 / (c + 3.0));
  }
  edm::MeshBridgeReport report;
  auto                  polyData = edm::MeshToPolyData(mesh.GetPointer(), edm::MeshBridgeOptions(), &report);
  EXPECT_EQ(report.SkippedCells, 0u);
  EXPECT_EQ(report.PointArrayName, "PointData");
  EXPECT_EQ(report.CellArrayName, "CellData");
  ASSERT_NE(polyData->GetPointData()->GetScalars(), nullptr);
  EXPECT_EQ(polyData->GetPointData()->GetScalars()->GetDataType(), VTK_DOUBLE);
  ASSERT_NE(polyData->GetCellData()->GetScalars(), nullptr);

  auto back = edm::PolyDataToMesh<MeshType>(polyData, edm::MeshBridgeOptions(), &report);
  EXPECT_EQ(report.SplitCells, 0u);
  ExpectSamePoints(mesh.GetPointer(), back.GetPointer());
  ExpectSameCells(mesh.GetPointer(), back.GetPointer());
  ASSERT_EQ(back->GetPointData()->Size(), 8u);
  for (unsigned int i = 0; i < 8; ++i)
  {
    EXPECT_EQ(back->GetPointData()->GetElement(i), 0.1 * i - 3.0);
  }
  ASSERT_EQ(back->GetCellData()->Size(), mesh->GetNumberOfCells());
  for (unsigned int c = 0; c < mesh->GetNumberOfCells(); ++c)
  {
    EXPECT_EQ(back->GetCellData()->GetElement(c), 1.0 / (c + 3.0));
  }
}

TEST(MeshBridge, ITKToVTKToITKIsExactWithVectorData)
{
  using VectorMeshType = itk::Mesh<itk::Vector<float, 3>, 3>;
  auto mesh = MakeMixedMesh<VectorMeshType>();
  for (unsigned int i = 0; i < 8; ++i)
  {
    itk::Vector<float, 3> v;
    v[0] = 0.25f * i;
    v[1] = -1.0f / (i + 1.0f);
    v[2] = 1e30f;
    mesh->SetPointData(i, v);
  }
  auto polyData = edm::MeshToPolyData(mesh.GetPointer());
  ASSERT_NE(polyData->GetPointData()->GetVectors(), nullptr);
  EXPECT_EQ(polyData->GetPointData()->GetVectors()->GetNumberOfComponents(), 3);
  EXPECT_EQ(polyData->GetPointData()->GetVectors()->GetDataType(), VTK_FLOAT);

  auto back = edm::PolyDataToMesh<VectorMeshType>(polyData);
  ExpectSamePoints(mesh.GetPointer(), back.GetPointer());
  ExpectSameCells(mesh.GetPointer(), back.GetPointer());
  for (unsigned int i = 0; i < 8; ++i)
  {
    EXPECT_EQ(back->GetPointData()->GetElement(i), mesh->GetPointData()->GetElement(i));
  }
}

TEST(MeshBridge, VariableLengthPixelsKeepTheirLength)
{
  using VariableMeshType = itk::Mesh<itk::VariableLengthVector<double>, 3>;
  auto mesh = MakeMixedMesh<VariableMeshType>();
  for (unsigned int i = 0; i < 8; ++i)
  {
    itk::VariableLengthVector<double> v(5);
    for (unsigned int c = 0; c < 5; ++c)
    {
      v[c] = i * 10.0 + c;
    }
    mesh->SetPointData(i, v);
  }
  auto           polyData = edm::MeshToPolyData(mesh.GetPointer());
  vtkDataArray * array = polyData->GetPointData()->GetArray("PointData");
  ASSERT_NE(array, nullptr);
  EXPECT_EQ(array->GetNumberOfComponents(), 5);
  EXPECT_EQ(array->GetComponent(3, 4), 34.0);
  auto back = edm::PolyDataToMesh<VariableMeshType>(polyData);
  for (unsigned int i = 0; i < 8; ++i)
  {
    EXPECT_EQ(back->GetPointData()->GetElement(i), mesh->GetPointData()->GetElement(i));
  }
}

TEST(MeshBridge, VTKToITKToVTKIsExact)
{
  vtkNew<vtkPolyData> polyData;
  vtkNew<vtkPoints>   points;
  points->SetDataType(VTK_DOUBLE);
  for (int i = 0; i < 9; ++i)
  {
    points->InsertNextPoint(0.5 * i, std::sqrt(2.0) * i, -1.0 / (i + 1));
  }
  polyData->SetPoints(points);
  vtkNew<vtkCellArray> verts;
  const vtkIdType      vert[1] = { 8 };
  verts->InsertNextCell(1, vert);
  vtkNew<vtkCellArray> lines;
  const vtkIdType      line[2] = { 0, 8 };
  const vtkIdType      polyline[5] = { 1, 2, 7, 6, 5 };
  lines->InsertNextCell(2, line);
  lines->InsertNextCell(5, polyline);
  vtkNew<vtkCellArray> polys;
  const vtkIdType      triangle[3] = { 0, 1, 2 };
  const vtkIdType      quad[4] = { 2, 3, 4, 5 };
  const vtkIdType      pentagon[5] = { 4, 5, 6, 7, 8 };
  polys->InsertNextCell(3, triangle);
  polys->InsertNextCell(4, quad);
  polys->InsertNextCell(5, pentagon);
  polyData->SetVerts(verts);
  polyData->SetLines(lines);
  polyData->SetPolys(polys);
  vtkNew<vtkDoubleArray> thickness;
  thickness->SetName("Thickness");
  for (int i = 0; i < 9; ++i)
  {
    thickness->InsertNextValue(i * i - 0.125);
  }
  polyData->GetPointData()->SetScalars(thickness);
  vtkNew<vtkDoubleArray> label;
  label->SetName("Label");
  for (int c = 0; c < 6; ++c)
  {
    label->InsertNextValue(100.0 + c);
  }
  polyData->GetCellData()->SetScalars(label);

  edm::MeshBridgeReport report;
  auto                  mesh = edm::PolyDataToMesh<MeshType>(polyData, edm::MeshBridgeOptions(), &report);
  EXPECT_EQ(report.PointArrayName, "Thickness");
  EXPECT_EQ(report.CellArrayName, "Label");
  ASSERT_EQ(mesh->GetNumberOfCells(), 6u);
  CellAutoPointer cell;
  mesh->GetCell(2, cell);
  EXPECT_EQ(cell->GetType(), itk::CommonEnums::CellGeometry::LINE_CELL);
  EXPECT_EQ(cell->GetNumberOfPoints(), 5u);
  mesh->GetCell(4, cell);
  EXPECT_EQ(cell->GetType(), itk::CommonEnums::CellGeometry::POLYGON_CELL);

  edm::MeshBridgeOptions names;
  names.PointArrayName = report.PointArrayName;
  names.CellArrayName = report.CellArrayName;
  auto back = edm::MeshToPolyData(mesh.GetPointer(), names);
  ASSERT_EQ(back->GetNumberOfPoints(), 9);
  for (vtkIdType i = 0; i < 9; ++i)
  {
    double a[3];
    double b[3];
    polyData->GetPoint(i, a);
    back->GetPoint(i, b);
    EXPECT_EQ(a[0], b[0]);
    EXPECT_EQ(a[1], b[1]);
    EXPECT_EQ(a[2], b[2]);
  }
  ExpectSameCellArray(polyData->GetVerts(), back->GetVerts());
  ExpectSameCellArray(polyData->GetLines(), back->GetLines());
  ExpectSameCellArray(polyData->GetPolys(), back->GetPolys());
  EXPECT_EQ(back->GetNumberOfStrips(), 0);
  ExpectSameArray(thickness, back->GetPointData()->GetScalars());
  ExpectSameArray(label, back->GetCellData()->GetScalars());
}

TEST(MeshBridge, NamedArrayIsChosenAndCheckedAgainstThePixel)
{
  vtkNew<vtkPolyData> polyData;
  vtkNew<vtkPoints>   points;
  points->InsertNextPoint(0, 0, 0);
  points->InsertNextPoint(1, 0, 0);
  polyData->SetPoints(points);
  vtkNew<vtkFloatArray> a;
  a->SetName("A");
  a->InsertNextValue(1.0f);
  a->InsertNextValue(2.0f);
  vtkNew<vtkIntArray> b;
  b->SetName("B");
  b->InsertNextValue(-7);
  b->InsertNextValue(9);
  vtkNew<vtkFloatArray> v;
  v->SetName("V");
  v->SetNumberOfComponents(3);
  v->InsertNextTuple3(1, 2, 3);
  v->InsertNextTuple3(4, 5, 6);
  polyData->GetPointData()->AddArray(a);
  polyData->GetPointData()->AddArray(b);
  polyData->GetPointData()->AddArray(v);

  edm::MeshBridgeOptions options;
  options.PointArrayName = "B";
  auto mesh = edm::PolyDataToMesh<MeshType>(polyData, options);
  EXPECT_EQ(mesh->GetPointData()->GetElement(0), -7.0);
  EXPECT_EQ(mesh->GetPointData()->GetElement(1), 9.0);

  options.PointArrayName = "V";
  EXPECT_THROW(edm::PolyDataToMesh<MeshType>(polyData, options), itk::ExceptionObject);
  options.PointArrayName = "Missing";
  EXPECT_THROW(edm::PolyDataToMesh<MeshType>(polyData, options), itk::ExceptionObject);

  // Without a name: the first array whose components fit the pixel.
  using VectorMeshType = itk::Mesh<itk::Vector<double, 3>, 3>;
  auto vectorMesh = edm::PolyDataToMesh<VectorMeshType>(polyData);
  EXPECT_EQ(vectorMesh->GetPointData()->GetElement(1)[2], 6.0);
}

TEST(MeshBridge, StripsAndPolyVerticesAreSplit)
{
  vtkNew<vtkPolyData> polyData;
  vtkNew<vtkPoints>   points;
  for (int i = 0; i < 6; ++i)
  {
    points->InsertNextPoint(i / 2, i % 2, 0.0);
  }
  polyData->SetPoints(points);
  vtkNew<vtkCellArray> strips;
  const vtkIdType      strip[6] = { 0, 1, 2, 3, 4, 5 };
  strips->InsertNextCell(6, strip);
  polyData->SetStrips(strips);
  vtkNew<vtkCellArray> verts;
  const vtkIdType      polyVertex[3] = { 0, 2, 4 };
  verts->InsertNextCell(3, polyVertex);
  polyData->SetVerts(verts);

  edm::MeshBridgeReport report;
  auto                  mesh = edm::PolyDataToMesh<MeshType>(polyData, edm::MeshBridgeOptions(), &report);
  EXPECT_EQ(report.SplitCells, 2u);
  ASSERT_EQ(mesh->GetNumberOfCells(), 3u + 4u);
  // Every triangle of the strip has the orientation of the first one (+z).
  for (unsigned int c = 3; c < 7; ++c)
  {
    CellAutoPointer cell;
    mesh->GetCell(c, cell);
    ASSERT_EQ(cell->GetType(), itk::CommonEnums::CellGeometry::TRIANGLE_CELL);
    const auto * ids = cell->PointIdsBegin();
    const auto   a = mesh->GetPoint(ids[0]);
    const auto   b = mesh->GetPoint(ids[1]);
    const auto   c2 = mesh->GetPoint(ids[2]);
    const double z = (b[0] - a[0]) * (c2[1] - a[1]) - (b[1] - a[1]) * (c2[0] - a[0]);
    EXPECT_LT(z, 0.0) << "triangle " << c;
  }
}

TEST(MeshBridge, QuadrilateralsBecomePolygonsAndVolumesAreSkipped)
{
  auto mesh = MeshType::New();
  for (unsigned int i = 0; i < 5; ++i)
  {
    MeshType::PointType p;
    p[0] = i;
    p[1] = i * i;
    p[2] = 1.0;
    mesh->SetPoint(i, p);
  }
  AddCell<MeshType, itk::QuadrilateralCell<CellType>>(mesh, { 0, 1, 2, 3 });
  AddCell<MeshType, itk::TetrahedronCell<CellType>>(mesh, { 0, 1, 2, 4 });
  edm::MeshBridgeReport report;
  auto                  polyData = edm::MeshToPolyData(mesh.GetPointer(), edm::MeshBridgeOptions(), &report);
  EXPECT_EQ(report.SkippedCells, 1u);
  ASSERT_EQ(polyData->GetNumberOfCells(), 1);
  EXPECT_EQ(polyData->GetCellType(0), VTK_QUAD);
  auto            back = edm::PolyDataToMesh<MeshType>(polyData);
  CellAutoPointer cell;
  ASSERT_TRUE(back->GetCell(0, cell));
  EXPECT_EQ(cell->GetType(), itk::CommonEnums::CellGeometry::POLYGON_CELL);
  const std::vector<MeshType::PointIdentifier> expected = { 0, 1, 2, 3 };
  EXPECT_TRUE(std::equal(expected.begin(), expected.end(), cell->PointIdsBegin()));
}

TEST(MeshBridge, SparsePointIdentifiersAreRenumbered)
{
  using Traits = itk::DefaultDynamicMeshTraits<double, 3, 3, double, double, double>;
  using SparseMeshType = itk::Mesh<double, 3, Traits>;
  auto mesh = SparseMeshType::New();
  for (unsigned int i : { 10u, 20u, 30u })
  {
    SparseMeshType::PointType p;
    p.Fill(i);
    mesh->SetPoint(i, p);
    mesh->SetPointData(i, i + 0.5);
  }
  AddCell<SparseMeshType, itk::TriangleCell<SparseMeshType::CellType>>(mesh, { 30, 10, 20 });
  auto polyData = edm::MeshToPolyData(mesh.GetPointer());
  ASSERT_EQ(polyData->GetNumberOfPoints(), 3);
  vtkNew<vtkIdList> ids;
  polyData->GetCellPoints(0, ids);
  ASSERT_EQ(ids->GetNumberOfIds(), 3);
  // Points in the container's order (10, 20, 30), so 30 is 2.
  EXPECT_EQ(ids->GetId(0), 2);
  EXPECT_EQ(ids->GetId(1), 0);
  EXPECT_EQ(ids->GetId(2), 1);
  EXPECT_EQ(polyData->GetPoint(2)[0], 30.0);
  EXPECT_EQ(polyData->GetPointData()->GetScalars()->GetComponent(2, 0), 30.5);
}

TEST(MeshBridge, InvalidInputsThrow)
{
  EXPECT_THROW(edm::MeshToPolyData<MeshType>(nullptr), itk::ExceptionObject);
  EXPECT_THROW(edm::PolyDataToMesh<MeshType>(nullptr), itk::ExceptionObject);

  auto mesh = MeshType::New();
  mesh->SetPoint(0, MeshType::PointType());
  AddCell<MeshType, itk::LineCell<CellType>>(mesh, { 0, 5 });
  EXPECT_THROW(edm::MeshToPolyData(mesh.GetPointer()), itk::ExceptionObject);

  vtkNew<vtkPolyData> polyData;
  vtkNew<vtkPoints>   points;
  points->InsertNextPoint(0, 0, 0);
  polyData->SetPoints(points);
  vtkNew<vtkCellArray> lines;
  const vtkIdType      line[2] = { 0, 3 };
  lines->InsertNextCell(2, line);
  polyData->SetLines(lines);
  EXPECT_THROW(edm::PolyDataToMesh<MeshType>(polyData), itk::ExceptionObject);
}

TEST(MeshBridge, ImageRoundTripKeepsGeometryAndPixels)
{
  using ImageType = itk::Image<itk::CovariantVector<float, 3>, 3>;
  auto                 image = ImageType::New();
  ImageType::IndexType start = { { -2, 3, 5 } };
  ImageType::SizeType  size = { { 4, 3, 2 } };
  image->SetRegions(ImageType::RegionType(start, size));
  ImageType::SpacingType spacing;
  spacing[0] = 0.5;
  spacing[1] = 1.25;
  spacing[2] = 3.0;
  image->SetSpacing(spacing);
  ImageType::PointType origin;
  origin[0] = -10.0;
  origin[1] = 2.5;
  origin[2] = 7.0;
  image->SetOrigin(origin);
  ImageType::DirectionType direction;
  direction.Fill(0.0);
  // A rotation of 90 degrees about z.
  direction(0, 1) = -1.0;
  direction(1, 0) = 1.0;
  direction(2, 2) = 1.0;
  image->SetDirection(direction);
  image->Allocate();
  float value = 0.0f;
  for (itk::ImageRegionIteratorWithIndex<ImageType> it(image, image->GetBufferedRegion()); !it.IsAtEnd(); ++it)
  {
    ImageType::PixelType pixel;
    pixel[0] = value;
    pixel[1] = -2.0f * value;
    pixel[2] = value * value;
    it.Set(pixel);
    value += 0.75f;
  }

  auto imageData = edm::ImageToImageData(image.GetPointer(), "Force");
  int  extent[6];
  imageData->GetExtent(extent);
  EXPECT_EQ(extent[0], -2);
  EXPECT_EQ(extent[1], 1);
  EXPECT_EQ(extent[2], 3);
  EXPECT_EQ(extent[3], 5);
  EXPECT_EQ(extent[4], 5);
  EXPECT_EQ(extent[5], 6);
  vtkDataArray * array = imageData->GetPointData()->GetVectors();
  ASSERT_NE(array, nullptr);
  EXPECT_STREQ(array->GetName(), "Force");
  // Same physical position of every voxel in both libraries.
  for (itk::ImageRegionIteratorWithIndex<ImageType> it(image, image->GetBufferedRegion()); !it.IsAtEnd(); ++it)
  {
    const auto           index = it.GetIndex();
    ImageType::PointType itkPoint;
    image->TransformIndexToPhysicalPoint(index, itkPoint);
    const int ijk[3] = { static_cast<int>(index[0]), static_cast<int>(index[1]), static_cast<int>(index[2]) };
    double    vtkPoint[3];
    imageData->TransformIndexToPhysicalPoint(ijk, vtkPoint);
    for (unsigned int d = 0; d < 3; ++d)
    {
      EXPECT_DOUBLE_EQ(itkPoint[d], vtkPoint[d]);
    }
    const vtkIdType id = imageData->ComputePointId(const_cast<int *>(ijk));
    for (int c = 0; c < 3; ++c)
    {
      EXPECT_EQ(array->GetComponent(id, c), it.Get()[c]);
    }
  }

  auto back = edm::ImageDataToImage<ImageType>(imageData, array);
  EXPECT_EQ(back->GetBufferedRegion(), image->GetBufferedRegion());
  EXPECT_EQ(back->GetOrigin(), image->GetOrigin());
  EXPECT_EQ(back->GetSpacing(), image->GetSpacing());
  EXPECT_EQ(back->GetDirection(), image->GetDirection());
  for (itk::ImageRegionIteratorWithIndex<ImageType> it(image, image->GetBufferedRegion()); !it.IsAtEnd(); ++it)
  {
    EXPECT_EQ(back->GetPixel(it.GetIndex()), it.Get());
  }

  // A one-component array does not fit a vector pixel.
  vtkNew<vtkFloatArray> scalars;
  scalars->SetNumberOfTuples(imageData->GetNumberOfPoints());
  EXPECT_THROW(edm::ImageDataToImage<ImageType>(imageData, scalars), itk::ExceptionObject);
}

// PolyLinesAsSegments: a polyline of n points becomes its n - 1 segments, in
// order, each an itk::LineCell (the 2-D filter's contours); two-point lines
// stay one segment; cell data, which no longer match cell for cell, are left
// out. The 2-D mesh drops z.
TEST(MeshBridge, PolyLinesAsSegmentsGivesOneLineCellPerSegment)
{
  vtkNew<vtkPolyData> polyData;
  vtkNew<vtkPoints>   points;
  for (int k = 0; k < 6; ++k)
  {
    points->InsertNextPoint(1.5 * k, -0.5 * k, 7.0);
  }
  vtkNew<vtkCellArray> lines;
  const vtkIdType      closed[5] = { 0, 1, 2, 3, 0 };
  const vtkIdType      segment[2] = { 4, 5 };
  lines->InsertNextCell(5, closed);
  lines->InsertNextCell(2, segment);
  polyData->SetPoints(points);
  polyData->SetLines(lines);
  vtkNew<vtkIntArray> label;
  label->SetName("Label");
  label->InsertNextValue(10);
  label->InsertNextValue(20);
  polyData->GetCellData()->AddArray(label);

  using ContourMeshType = itk::Mesh<int, 2, itk::DefaultStaticMeshTraits<int, 2, 2, double, double, int>>;
  edm::MeshBridgeOptions options;
  options.PolyLinesAsSegments = true;
  edm::MeshBridgeReport report;
  auto                  mesh = edm::PolyDataToMesh<ContourMeshType>(polyData, options, &report);
  ASSERT_EQ(mesh->GetNumberOfCells(), 5u);
  EXPECT_EQ(report.SplitCells, 1u);
  EXPECT_EQ(report.CellArrayName, "");
  const itk::IdentifierType expected[5][2] = { { 0, 1 }, { 1, 2 }, { 2, 3 }, { 3, 0 }, { 4, 5 } };
  for (itk::IdentifierType c = 0; c < 5; ++c)
  {
    ContourMeshType::CellAutoPointer cell;
    ASSERT_TRUE(mesh->GetCell(c, cell));
    EXPECT_EQ(cell->GetType(), itk::CommonEnums::CellGeometry::LINE_CELL);
    ASSERT_EQ(cell->GetNumberOfPoints(), 2u);
    EXPECT_EQ(cell->PointIdsBegin()[0], expected[c][0]) << c;
    EXPECT_EQ(cell->PointIdsBegin()[1], expected[c][1]) << c;
  }
  EXPECT_EQ(mesh->GetPoint(3)[0], 4.5);
  EXPECT_EQ(mesh->GetPoint(3)[1], -1.5);

  // Without the option: one polyline cell and the cell data.
  auto whole = edm::PolyDataToMesh<ContourMeshType>(polyData);
  EXPECT_EQ(whole->GetNumberOfCells(), 2u);
  ASSERT_NE(whole->GetCellData(), nullptr);
  EXPECT_EQ(whole->GetCellData()->ElementAt(1), 20);
}

// A 2-D vtkImageData becomes a 2-D itk::Image with its in-plane geometry; a
// direction matrix that mixes z with x and y (a plane that is not z = const)
// is refused.
TEST(MeshBridge, PlanarImageKeepsItsPlaneOrIsRefused)
{
  using ImageType = itk::Image<float, 2>;
  vtkNew<vtkImageData> imageData;
  imageData->SetExtent(2, 5, -1, 1, 4, 4);
  imageData->SetOrigin(1.0, 2.0, 3.0);
  imageData->SetSpacing(0.5, 2.0, 9.0);
  imageData->SetDirectionMatrix(0.0, -1.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0);
  vtkNew<vtkFloatArray> values;
  values->SetNumberOfTuples(imageData->GetNumberOfPoints());
  for (vtkIdType i = 0; i < imageData->GetNumberOfPoints(); ++i)
  {
    values->SetValue(i, static_cast<float>(i));
  }
  auto image = edm::ImageDataToImage<ImageType>(imageData, values);
  EXPECT_EQ(image->GetBufferedRegion().GetIndex()[0], 2);
  EXPECT_EQ(image->GetBufferedRegion().GetIndex()[1], -1);
  EXPECT_EQ(image->GetBufferedRegion().GetSize()[0], 4u);
  EXPECT_EQ(image->GetBufferedRegion().GetSize()[1], 3u);
  // Same in-plane position of every pixel in both libraries.
  for (int j = -1; j <= 1; ++j)
  {
    for (int i = 2; i <= 5; ++i)
    {
      ImageType::IndexType index = { { i, j } };
      ImageType::PointType itkPoint;
      image->TransformIndexToPhysicalPoint(index, itkPoint);
      double vtkPoint[3];
      imageData->TransformIndexToPhysicalPoint(i, j, 4, vtkPoint);
      EXPECT_DOUBLE_EQ(itkPoint[0], vtkPoint[0]);
      EXPECT_DOUBLE_EQ(itkPoint[1], vtkPoint[1]);
      int ijk[3] = { i, j, 4 };
      EXPECT_EQ(image->GetPixel(index), values->GetValue(imageData->ComputePointId(ijk)));
    }
  }
  imageData->SetDirectionMatrix(1.0, 0.0, 0.0, 0.0, 0.8, -0.6, 0.0, 0.6, 0.8);
  EXPECT_THROW(edm::ImageDataToImage<ImageType>(imageData, values), itk::ExceptionObject);
}
