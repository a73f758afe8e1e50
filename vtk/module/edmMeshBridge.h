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
#ifndef edmMeshBridge_h
#define edmMeshBridge_h

#include "edmPolyLineCell.h"

#include "itkDefaultConvertPixelTraits.h"
#include "itkImage.h"
#include "itkImageRegionConstIteratorWithIndex.h"
#include "itkLineCell.h"
#include "itkMacro.h"
#include "itkMesh.h"
#include "itkPolygonCell.h"
#include "itkTriangleCell.h"
#include "itkVariableLengthVector.h"
#include "itkVertexCell.h"

#include "vtkAOSDataArrayTemplate.h"
#include "vtkCellArray.h"
#include "vtkCellArrayIterator.h"
#include "vtkCellData.h"
#include "vtkDataArray.h"
#include "vtkImageData.h"
#include "vtkMatrix3x3.h"
#include "vtkPointData.h"
#include "vtkPoints.h"
#include "vtkPolyData.h"
#include "vtkSmartPointer.h"
#include "vtkTypeTraits.h"

#include <cmath>
#include <string>
#include <type_traits>
#include <unordered_map>
#include <vector>

/** \file edmMeshBridge.h
 * \brief Conversions between itk::Mesh and vtkPolyData, and between itk::Image
 * and vtkImageData.
 *
 * Cells (VTK cell arrays on the left, ITK cells on the right):
 * - Verts: a one-point cell <-> itk::VertexCell. A poly-vertex (several
 *   points in one verts cell) becomes one VertexCell per point.
 * - Lines: a two-point cell <-> itk::LineCell; a longer polyline <->
 *   edm::PolyLineCell (a LINE_CELL with any number of points: ITK 5.2 has no
 *   polyline cell), or, with MeshBridgeOptions::PolyLinesAsSegments, one
 *   itk::LineCell per segment (the form the 2-D contours of
 *   itk::DeformableMeshFilter take: a chain of segments, closed when it
 *   comes back to its first point).
 * - Polys: a three-point cell <-> itk::TriangleCell; four points or more <->
 *   itk::PolygonCell. An itk::QuadrilateralCell becomes a four-point polygon
 *   (it comes back as an itk::PolygonCell with the same points).
 * - Strips: each strip becomes its triangles (consistently oriented).
 * - Other ITK cells (tetrahedra, hexahedra, quadratic cells) have no place in
 *   a vtkPolyData: they are skipped and counted in MeshBridgeReport.
 *
 * ITK cell identifiers follow VTK's cell order (verts, lines, polys, strips),
 * so a vtkPolyData goes to ITK and back unchanged. An itk::Mesh goes to VTK and
 * back unchanged when its cells are already in that order (all vertices, then
 * lines, then surface cells) and its point identifiers run from 0 to N-1;
 * otherwise the points and cells are the same but renumbered.
 *
 * Point and cell data: an itk::Mesh holds one pixel per point and one per cell.
 * A scalar pixel type gives a one-component VTK array, an itk::Vector,
 * CovariantVector, FixedArray, RGBPixel... of N components an N-component
 * array, an itk::VariableLengthVector an array of its length. The VTK array's
 * value type is the pixel's component type. Going from VTK to ITK, the array
 * read is the one named in MeshBridgeOptions, else the active scalars or
 * vectors, else the first array whose number of components fits the pixel.
 * Values are converted to the pixel's component type.
 *
 * Coordinates: VTK points of the ITK coordinate type, the traits'
 * CoordRepType: float for itk::Mesh<double, 3> (ITK's default traits), double
 * for edm::PolyDataMeshType. Values are copied exactly when the ITK type holds
 * them (float VTK points always; double VTK points with PolyDataMeshType). Meshes of dimension 2 get
 * z = 0 in VTK and drop z coming back.
 *
 * Errors (a cell that refers to a missing point, an array whose number of
 * components does not fit the pixel, a null input) throw itk::ExceptionObject.
 *
 * \ingroup ExplicitDeformableModelVTK
 */
namespace edm
{

/** An itk::Mesh with double coordinates (itk::Mesh<double, 3> has float ones:
 * its traits' CoordRepType is float). It holds a vtkPolyData of double points
 * exactly; the VTK algorithms of this module compute with it. */
using PolyDataMeshType = itk::Mesh<double, 3, itk::DefaultStaticMeshTraits<double, 3, 3, double, double, double>>;

/** The 2-D counterpart of PolyDataMeshType: contours (x, y) with double
 * coordinates, as the VTK algorithms of this module compute them over a 2-D
 * image (a vtkImageData of nx x ny x 1 points). */
using ContourMeshType = itk::Mesh<double, 2, itk::DefaultStaticMeshTraits<double, 2, 2, double, double, double>>;

/** Options of the mesh conversions. */
struct MeshBridgeOptions
{
  /** ITK to VTK: name given to the point data array (default "PointData").
   * VTK to ITK: name of the point array to read ("" chooses, see above). */
  std::string PointArrayName;
  /** Same for the cell data array (default "CellData"). */
  std::string CellArrayName;
  /** Convert point data. Default: true. */
  bool PointData{ true };
  /** Convert cell data. Default: true. */
  bool CellData{ true };
  /** VTK to ITK: each polyline of n points becomes n - 1 itk::LineCell
   * (its segments, in order) instead of one edm::PolyLineCell. The ITK cell
   * identifiers then no longer follow VTK's cells one for one, so cell data
   * are not converted. Default: false. */
  bool PolyLinesAsSegments{ false };
};

/** What a mesh conversion did. */
struct MeshBridgeReport
{
  /** ITK cells with no vtkPolyData counterpart, left out. */
  std::size_t SkippedCells{ 0 };
  /** VTK cells split into several ITK cells (poly-vertices, strips). */
  std::size_t SplitCells{ 0 };
  /** Names of the arrays converted, empty when none was. */
  std::string PointArrayName;
  std::string CellArrayName;
};

namespace detail
{
template <typename T>
struct IsVariableLengthVector : std::false_type
{};
template <typename T>
struct IsVariableLengthVector<itk::VariableLengthVector<T>> : std::true_type
{};

template <typename TPixel>
using ComponentType = typename itk::DefaultConvertPixelTraits<TPixel>::ComponentType;

/** Number of components of a pixel (0 for a variable-length pixel: any). */
template <typename TPixel>
unsigned int
FixedNumberOfComponents()
{
  if constexpr (IsVariableLengthVector<TPixel>::value)
  {
    return 0;
  }
  else
  {
    return itk::DefaultConvertPixelTraits<TPixel>::GetNumberOfComponents();
  }
}

template <typename TPixel>
unsigned int
NumberOfComponents(const TPixel & pixel)
{
  if constexpr (IsVariableLengthVector<TPixel>::value)
  {
    return pixel.GetSize();
  }
  else
  {
    (void)pixel;
    return itk::DefaultConvertPixelTraits<TPixel>::GetNumberOfComponents();
  }
}

template <typename TPixel>
ComponentType<TPixel>
GetComponent(const TPixel & pixel, unsigned int c)
{
  if constexpr (std::is_arithmetic<TPixel>::value)
  {
    (void)c;
    return pixel;
  }
  else
  {
    return itk::DefaultConvertPixelTraits<TPixel>::GetNthComponent(static_cast<int>(c), pixel);
  }
}

template <typename TPixel>
void
SetComponent(TPixel & pixel, unsigned int c, ComponentType<TPixel> value)
{
  if constexpr (std::is_arithmetic<TPixel>::value)
  {
    (void)c;
    pixel = value;
  }
  else
  {
    itk::DefaultConvertPixelTraits<TPixel>::SetNthComponent(static_cast<int>(c), pixel, value);
  }
}

/** A VTK array of the VTK type matching T (vtkDoubleArray for double...). */
template <typename T>
vtkSmartPointer<vtkAOSDataArrayTemplate<T>>
NewArray(const std::string & name, unsigned int numberOfComponents, vtkIdType numberOfTuples)
{
  vtkSmartPointer<vtkDataArray> array;
  array.TakeReference(vtkDataArray::CreateDataArray(vtkTypeTraits<T>::VTKTypeID()));
  auto * typed = vtkAOSDataArrayTemplate<T>::FastDownCast(array);
  typed->SetNumberOfComponents(static_cast<int>(numberOfComponents));
  typed->SetNumberOfTuples(numberOfTuples);
  typed->SetName(name.c_str());
  return typed;
}

/** Reads component c of tuple i exactly when the array holds values of type
 * T, through double otherwise. */
template <typename T>
T
ReadValue(vtkDataArray * array, vtkIdType i, int c)
{
  if (auto * typed = vtkAOSDataArrayTemplate<T>::FastDownCast(array))
  {
    return typed->GetTypedComponent(i, c);
  }
  return static_cast<T>(array->GetComponent(i, c));
}

/** Fills a VTK array with the pixels of a container, visited in \a order. */
template <typename TContainer>
vtkSmartPointer<vtkDataArray>
ContainerToArray(const TContainer *                                          container,
                 const std::vector<typename TContainer::ElementIdentifier> & order,
                 const std::string &                                         name)
{
  using PixelType = typename TContainer::Element;
  using ValueType = ComponentType<PixelType>;
  if (container == nullptr || order.empty())
  {
    return nullptr;
  }
  PixelType first;
  if (!container->GetElementIfIndexExists(order.front(), &first))
  {
    return nullptr;
  }
  const unsigned int numberOfComponents = NumberOfComponents(first);
  if (numberOfComponents == 0)
  {
    return nullptr;
  }
  auto array = NewArray<ValueType>(name, numberOfComponents, static_cast<vtkIdType>(order.size()));
  for (std::size_t i = 0; i < order.size(); ++i)
  {
    PixelType pixel;
    if (!container->GetElementIfIndexExists(order[i], &pixel) || NumberOfComponents(pixel) != numberOfComponents)
    {
      return nullptr; // Incomplete or ragged data: not representable as one array.
    }
    for (unsigned int c = 0; c < numberOfComponents; ++c)
    {
      array->SetTypedComponent(static_cast<vtkIdType>(i), static_cast<int>(c), GetComponent(pixel, c));
    }
  }
  return array;
}

/** The array of \a attributes to convert into pixels of type TPixel. */
template <typename TPixel>
vtkDataArray *
ChooseArray(vtkDataSetAttributes * attributes, const std::string & name)
{
  const unsigned int wanted = FixedNumberOfComponents<TPixel>();
  auto               fits = [wanted](vtkDataArray * array) {
    return array != nullptr && array->GetNumberOfComponents() > 0 &&
           (wanted == 0 || static_cast<unsigned int>(array->GetNumberOfComponents()) == wanted);
  };
  if (!name.empty())
  {
    vtkDataArray * array = attributes->GetArray(name.c_str());
    if (array == nullptr)
    {
      itkGenericExceptionMacro("edm::PolyDataToMesh: no array named \"" << name << "\".");
    }
    if (!fits(array))
    {
      itkGenericExceptionMacro("edm::PolyDataToMesh: array \"" << name << "\" has " << array->GetNumberOfComponents()
                                                               << " components; the mesh pixel has " << wanted << ".");
    }
    return array;
  }
  if (fits(attributes->GetScalars()))
  {
    return attributes->GetScalars();
  }
  if (fits(attributes->GetVectors()))
  {
    return attributes->GetVectors();
  }
  for (int k = 0; k < attributes->GetNumberOfArrays(); ++k)
  {
    if (fits(attributes->GetArray(k)))
    {
      return attributes->GetArray(k);
    }
  }
  return nullptr;
}

/** Fills a pixel container of \a count elements (identifiers 0..count-1) from a VTK array. */
template <typename TContainer>
typename TContainer::Pointer
ArrayToContainer(vtkDataArray * array, vtkIdType count)
{
  using PixelType = typename TContainer::Element;
  using ValueType = ComponentType<PixelType>;
  const int numberOfComponents = array->GetNumberOfComponents();
  auto      container = TContainer::New();
  container->Reserve(static_cast<typename TContainer::ElementIdentifier>(count));
  for (vtkIdType i = 0; i < count; ++i)
  {
    PixelType pixel;
    if constexpr (IsVariableLengthVector<PixelType>::value)
    {
      pixel.SetSize(static_cast<unsigned int>(numberOfComponents));
    }
    for (int c = 0; c < numberOfComponents; ++c)
    {
      SetComponent(pixel, static_cast<unsigned int>(c), ReadValue<ValueType>(array, i, c));
    }
    container->InsertElement(static_cast<typename TContainer::ElementIdentifier>(i), pixel);
  }
  return container;
}

inline void
SetActiveAttribute(vtkDataSetAttributes * attributes, vtkDataArray * array)
{
  attributes->AddArray(array);
  if (array->GetNumberOfComponents() == 1)
  {
    attributes->SetActiveScalars(array->GetName());
  }
  else if (array->GetNumberOfComponents() == 3)
  {
    attributes->SetActiveVectors(array->GetName());
  }
}
} // end namespace detail

/** Converts an itk::Mesh into a new vtkPolyData (see the file documentation
 * for the mapping). Throws itk::ExceptionObject when \a mesh is null or a cell
 * refers to a point that does not exist. */
template <typename TMesh>
vtkSmartPointer<vtkPolyData>
MeshToPolyData(const TMesh *             mesh,
               const MeshBridgeOptions & options = MeshBridgeOptions(),
               MeshBridgeReport *        report = nullptr)
{
  using PointIdentifier = typename TMesh::PointIdentifier;
  using CellIdentifier = typename TMesh::CellIdentifier;
  using CoordinateType = typename TMesh::CoordRepType;
  constexpr unsigned int Dimension = TMesh::PointDimension;
  static_assert(Dimension >= 1 && Dimension <= 3, "vtkPolyData holds points of dimension 1 to 3.");

  if (mesh == nullptr)
  {
    itkGenericExceptionMacro("edm::MeshToPolyData: the mesh is null.");
  }
  MeshBridgeReport   localReport;
  MeshBridgeReport & result = report != nullptr ? *report : localReport;
  result = MeshBridgeReport();

  auto polyData = vtkSmartPointer<vtkPolyData>::New();

  // Points, with a map from ITK identifiers to VTK ones when they are not 0..N-1.
  const auto *                                   points = mesh->GetPoints();
  const vtkIdType                                numberOfPoints = points != nullptr ? points->Size() : 0;
  std::vector<PointIdentifier>                   pointOrder;
  std::unordered_map<PointIdentifier, vtkIdType> idMap;
  bool                                           contiguous = true;
  auto                                           coordinates = vtkSmartPointer<vtkPoints>::New();
  coordinates->SetDataType(vtkTypeTraits<CoordinateType>::VTKTypeID());
  coordinates->SetNumberOfPoints(numberOfPoints);
  auto * coordinateArray = vtkAOSDataArrayTemplate<CoordinateType>::FastDownCast(coordinates->GetData());
  if (numberOfPoints > 0)
  {
    pointOrder.reserve(numberOfPoints);
    vtkIdType i = 0;
    for (auto it = points->Begin(); it != points->End(); ++it, ++i)
    {
      contiguous = contiguous && it.Index() == static_cast<PointIdentifier>(i);
      pointOrder.push_back(it.Index());
      const auto & p = it.Value();
      for (unsigned int d = 0; d < 3; ++d)
      {
        coordinateArray->SetTypedComponent(i, static_cast<int>(d), d < Dimension ? p[d] : CoordinateType(0));
      }
    }
    if (!contiguous)
    {
      for (vtkIdType k = 0; k < numberOfPoints; ++k)
      {
        idMap[pointOrder[k]] = k;
      }
    }
  }
  polyData->SetPoints(coordinates);

  // Cells, sorted into VTK's four arrays; cellOrder records which ITK cell each
  // VTK cell came from, in VTK's cell order.
  auto                        verts = vtkSmartPointer<vtkCellArray>::New();
  auto                        lines = vtkSmartPointer<vtkCellArray>::New();
  auto                        polys = vtkSmartPointer<vtkCellArray>::New();
  std::vector<CellIdentifier> vertOrder;
  std::vector<CellIdentifier> lineOrder;
  std::vector<CellIdentifier> polyOrder;
  std::vector<vtkIdType>      ids;
  if (mesh->GetCells() != nullptr)
  {
    for (auto it = mesh->GetCells()->Begin(); it != mesh->GetCells()->End(); ++it)
    {
      const auto * cell = it.Value();
      const auto   n = static_cast<vtkIdType>(cell->GetNumberOfPoints());
      ids.resize(n);
      const auto * pointIds = cell->PointIdsBegin();
      for (vtkIdType k = 0; k < n; ++k)
      {
        if (contiguous)
        {
          if (pointIds[k] >= static_cast<PointIdentifier>(numberOfPoints))
          {
            itkGenericExceptionMacro("edm::MeshToPolyData: cell " << it.Index() << " refers to point " << pointIds[k]
                                                                  << ", but the mesh has " << numberOfPoints
                                                                  << " points.");
          }
          ids[k] = static_cast<vtkIdType>(pointIds[k]);
        }
        else
        {
          const auto found = idMap.find(pointIds[k]);
          if (found == idMap.end())
          {
            itkGenericExceptionMacro("edm::MeshToPolyData: cell " << it.Index() << " refers to point " << pointIds[k]
                                                                  << ", which does not exist.");
          }
          ids[k] = found->second;
        }
      }
      switch (cell->GetType())
      {
        case itk::CommonEnums::CellGeometry::VERTEX_CELL:
          verts->InsertNextCell(n, ids.data());
          vertOrder.push_back(it.Index());
          break;
        case itk::CommonEnums::CellGeometry::LINE_CELL:
          lines->InsertNextCell(n, ids.data());
          lineOrder.push_back(it.Index());
          break;
        case itk::CommonEnums::CellGeometry::TRIANGLE_CELL:
        case itk::CommonEnums::CellGeometry::QUADRILATERAL_CELL:
        case itk::CommonEnums::CellGeometry::POLYGON_CELL:
          polys->InsertNextCell(n, ids.data());
          polyOrder.push_back(it.Index());
          break;
        default:
          ++result.SkippedCells;
          break;
      }
    }
  }
  if (verts->GetNumberOfCells() > 0)
  {
    polyData->SetVerts(verts);
  }
  if (lines->GetNumberOfCells() > 0)
  {
    polyData->SetLines(lines);
  }
  if (polys->GetNumberOfCells() > 0)
  {
    polyData->SetPolys(polys);
  }

  if (options.PointData && numberOfPoints > 0)
  {
    const std::string name = options.PointArrayName.empty() ? "PointData" : options.PointArrayName;
    if (auto array = detail::ContainerToArray(mesh->GetPointData(), pointOrder, name))
    {
      detail::SetActiveAttribute(polyData->GetPointData(), array);
      result.PointArrayName = name;
    }
  }
  if (options.CellData)
  {
    std::vector<CellIdentifier> cellOrder(vertOrder);
    cellOrder.insert(cellOrder.end(), lineOrder.begin(), lineOrder.end());
    cellOrder.insert(cellOrder.end(), polyOrder.begin(), polyOrder.end());
    const std::string name = options.CellArrayName.empty() ? "CellData" : options.CellArrayName;
    if (auto array = detail::ContainerToArray(mesh->GetCellData(), cellOrder, name))
    {
      detail::SetActiveAttribute(polyData->GetCellData(), array);
      result.CellArrayName = name;
    }
  }
  return polyData;
}

/** Converts a vtkPolyData into a new itk::Mesh (see the file documentation for
 * the mapping). Throws itk::ExceptionObject when \a polyData is null, a cell
 * refers to a point that does not exist, or a named array does not exist or
 * does not fit the pixel type. */
template <typename TMesh>
typename TMesh::Pointer
PolyDataToMesh(vtkPolyData *             polyData,
               const MeshBridgeOptions & options = MeshBridgeOptions(),
               MeshBridgeReport *        report = nullptr)
{
  using CellType = typename TMesh::CellType;
  using CellAutoPointer = typename CellType::CellAutoPointer;
  using PointIdentifier = typename TMesh::PointIdentifier;
  using CellIdentifier = typename TMesh::CellIdentifier;
  using PointType = typename TMesh::PointType;
  using CoordinateType = typename TMesh::CoordRepType;
  constexpr unsigned int Dimension = TMesh::PointDimension;
  static_assert(Dimension >= 1 && Dimension <= 3, "vtkPolyData holds points of dimension 1 to 3.");

  if (polyData == nullptr)
  {
    itkGenericExceptionMacro("edm::PolyDataToMesh: the polydata is null.");
  }
  MeshBridgeReport   localReport;
  MeshBridgeReport & result = report != nullptr ? *report : localReport;
  result = MeshBridgeReport();

  auto            mesh = TMesh::New();
  const vtkIdType numberOfPoints = polyData->GetNumberOfPoints();
  auto            points = TMesh::PointsContainer::New();
  points->Reserve(static_cast<PointIdentifier>(numberOfPoints));
  vtkDataArray * coordinates = numberOfPoints > 0 ? polyData->GetPoints()->GetData() : nullptr;
  for (vtkIdType i = 0; i < numberOfPoints; ++i)
  {
    PointType p;
    for (unsigned int d = 0; d < Dimension; ++d)
    {
      p[d] = detail::ReadValue<CoordinateType>(coordinates, i, static_cast<int>(d));
    }
    points->InsertElement(static_cast<PointIdentifier>(i), p);
  }
  mesh->SetPoints(points);

  CellIdentifier               cellId = 0;
  std::vector<PointIdentifier> ids;
  auto                         addCell = [&](auto * cell, const PointIdentifier * first, const PointIdentifier * last) {
    CellAutoPointer pointer;
    pointer.TakeOwnership(cell);
    pointer->SetPointIds(first, last);
    mesh->SetCell(cellId++, pointer);
  };
  auto visit = [&](vtkCellArray * cells, auto && convert) {
    if (cells == nullptr)
    {
      return;
    }
    auto iterator = vtk::TakeSmartPointer(cells->NewIterator());
    for (iterator->GoToFirstCell(); !iterator->IsDoneWithTraversal(); iterator->GoToNextCell())
    {
      vtkIdType         n = 0;
      const vtkIdType * vtkIds = nullptr;
      iterator->GetCurrentCell(n, vtkIds);
      ids.resize(n);
      for (vtkIdType k = 0; k < n; ++k)
      {
        if (vtkIds[k] < 0 || vtkIds[k] >= numberOfPoints)
        {
          itkGenericExceptionMacro("edm::PolyDataToMesh: a cell refers to point "
                                   << vtkIds[k] << ", but the polydata has " << numberOfPoints << " points.");
        }
        ids[k] = static_cast<PointIdentifier>(vtkIds[k]);
      }
      convert(n);
    }
  };

  visit(polyData->GetVerts(), [&](vtkIdType n) {
    for (vtkIdType k = 0; k < n; ++k)
    {
      addCell(new itk::VertexCell<CellType>, &ids[k], &ids[k] + 1);
    }
    result.SplitCells += n > 1 ? 1 : 0;
  });
  visit(polyData->GetLines(), [&](vtkIdType n) {
    if (options.PolyLinesAsSegments)
    {
      for (vtkIdType k = 0; k + 1 < n; ++k)
      {
        addCell(new itk::LineCell<CellType>, &ids[k], &ids[k] + 2);
      }
      result.SplitCells += n > 2 ? 1 : 0;
    }
    else if (n == 2)
    {
      addCell(new itk::LineCell<CellType>, ids.data(), ids.data() + 2);
    }
    else if (n > 2)
    {
      addCell(new PolyLineCell<CellType>, ids.data(), ids.data() + n);
    }
  });
  visit(polyData->GetPolys(), [&](vtkIdType n) {
    if (n == 3)
    {
      addCell(new itk::TriangleCell<CellType>, ids.data(), ids.data() + 3);
    }
    else if (n > 3)
    {
      addCell(new itk::PolygonCell<CellType>, ids.data(), ids.data() + n);
    }
  });
  visit(polyData->GetStrips(), [&](vtkIdType n) {
    for (vtkIdType k = 0; k + 2 < n; ++k)
    {
      // Odd triangles of a strip are flipped to keep one orientation.
      const PointIdentifier triangle[3] = { ids[k + (k % 2)], ids[k + 1 - (k % 2)], ids[k + 2] };
      addCell(new itk::TriangleCell<CellType>, triangle, triangle + 3);
    }
    result.SplitCells += n > 3 ? 1 : 0;
  });

  if (options.PointData && numberOfPoints > 0)
  {
    if (vtkDataArray * array =
          detail::ChooseArray<typename TMesh::PixelType>(polyData->GetPointData(), options.PointArrayName))
    {
      mesh->SetPointData(detail::ArrayToContainer<typename TMesh::PointDataContainer>(array, numberOfPoints));
      result.PointArrayName = array->GetName() != nullptr ? array->GetName() : "";
    }
  }
  if (options.CellData && !options.PolyLinesAsSegments &&
      static_cast<vtkIdType>(cellId) == polyData->GetNumberOfCells() && cellId > 0)
  {
    if (vtkDataArray * array =
          detail::ChooseArray<typename TMesh::CellPixelType>(polyData->GetCellData(), options.CellArrayName))
    {
      mesh->SetCellData(
        detail::ArrayToContainer<typename TMesh::CellDataContainer>(array, static_cast<vtkIdType>(cellId)));
      result.CellArrayName = array->GetName() != nullptr ? array->GetName() : "";
    }
  }
  return mesh;
}

/** Copies an itk::Image (scalar or fixed-length vector pixels, dimension 1 to
 * 3) into a new vtkImageData: extent from the buffered region's index and
 * size, origin, spacing and direction preserved (VTK 9 image geometry), the
 * pixels in a point array named \a arrayName set as active scalars (one
 * component) or vectors (three). */
template <typename TImage>
vtkSmartPointer<vtkImageData>
ImageToImageData(const TImage * image, const std::string & arrayName = "ImageScalars")
{
  using PixelType = typename TImage::PixelType;
  using ValueType = detail::ComponentType<PixelType>;
  constexpr unsigned int Dimension = TImage::ImageDimension;
  static_assert(Dimension >= 1 && Dimension <= 3, "vtkImageData holds images of dimension 1 to 3.");
  if (image == nullptr)
  {
    itkGenericExceptionMacro("edm::ImageToImageData: the image is null.");
  }
  const auto region = image->GetBufferedRegion();
  int        extent[6] = { 0, 0, 0, 0, 0, 0 };
  double     origin[3] = { 0.0, 0.0, 0.0 };
  double     spacing[3] = { 1.0, 1.0, 1.0 };
  auto       direction = vtkSmartPointer<vtkMatrix3x3>::New();
  for (unsigned int d = 0; d < Dimension; ++d)
  {
    extent[2 * d] = static_cast<int>(region.GetIndex()[d]);
    extent[2 * d + 1] = static_cast<int>(region.GetIndex()[d] + static_cast<long>(region.GetSize()[d]) - 1);
    origin[d] = image->GetOrigin()[d];
    spacing[d] = image->GetSpacing()[d];
    for (unsigned int e = 0; e < Dimension; ++e)
    {
      direction->SetElement(static_cast<int>(d), static_cast<int>(e), image->GetDirection()(d, e));
    }
  }
  auto imageData = vtkSmartPointer<vtkImageData>::New();
  imageData->SetExtent(extent);
  imageData->SetOrigin(origin);
  imageData->SetSpacing(spacing);
  imageData->SetDirectionMatrix(direction);

  const auto         numberOfPixels = static_cast<vtkIdType>(region.GetNumberOfPixels());
  const unsigned int numberOfComponents =
    numberOfPixels > 0 ? detail::NumberOfComponents(image->GetPixel(region.GetIndex())) : 1;
  auto array = detail::NewArray<ValueType>(arrayName, numberOfComponents, numberOfPixels);
  // ITK's and VTK's buffers both run x fastest: the i-th pixel is the i-th tuple.
  vtkIdType i = 0;
  for (itk::ImageRegionConstIteratorWithIndex<TImage> it(image, region); !it.IsAtEnd(); ++it, ++i)
  {
    const PixelType & pixel = it.Get();
    for (unsigned int c = 0; c < numberOfComponents; ++c)
    {
      array->SetTypedComponent(i, static_cast<int>(c), detail::GetComponent(pixel, c));
    }
  }
  detail::SetActiveAttribute(imageData->GetPointData(), array);
  return imageData;
}

/** Copies a point array of a vtkImageData into a new itk::Image (dimension 3,
 * or lower when the image is flat along the last axes) with the same extent,
 * origin, spacing and direction. The array must have as many tuples as the
 * image has points and as many components as TImage's pixel. A 2-D image
 * (nx x ny x 1) lies in a plane z = const: its direction matrix must not
 * mix z with x and y (a plane of another orientation has no 2-D ITK
 * counterpart). Throws itk::ExceptionObject otherwise. */
template <typename TImage>
typename TImage::Pointer
ImageDataToImage(vtkImageData * imageData, vtkDataArray * array)
{
  using PixelType = typename TImage::PixelType;
  using ValueType = detail::ComponentType<PixelType>;
  constexpr unsigned int Dimension = TImage::ImageDimension;
  static_assert(Dimension >= 1 && Dimension <= 3, "vtkImageData holds images of dimension 1 to 3.");
  static_assert(!detail::IsVariableLengthVector<PixelType>::value, "Use a fixed-length pixel type.");
  if (imageData == nullptr || array == nullptr)
  {
    itkGenericExceptionMacro("edm::ImageDataToImage: the image or its array is null.");
  }
  const unsigned int numberOfComponents = detail::FixedNumberOfComponents<PixelType>();
  if (static_cast<unsigned int>(array->GetNumberOfComponents()) != numberOfComponents)
  {
    itkGenericExceptionMacro("edm::ImageDataToImage: array \"" << (array->GetName() ? array->GetName() : "")
                                                               << "\" has " << array->GetNumberOfComponents()
                                                               << " components; the pixel has " << numberOfComponents
                                                               << ".");
  }
  if (array->GetNumberOfTuples() != imageData->GetNumberOfPoints())
  {
    itkGenericExceptionMacro("edm::ImageDataToImage: the array has "
                             << array->GetNumberOfTuples() << " tuples, the image " << imageData->GetNumberOfPoints()
                             << " points.");
  }
  int extent[6];
  imageData->GetExtent(extent);
  for (unsigned int d = Dimension; d < 3; ++d)
  {
    if (extent[2 * d] != extent[2 * d + 1])
    {
      itkGenericExceptionMacro("edm::ImageDataToImage: the vtkImageData has more than " << Dimension << " dimensions.");
    }
  }
  typename TImage::IndexType     index;
  typename TImage::SizeType      size;
  typename TImage::PointType     origin;
  typename TImage::SpacingType   spacing;
  typename TImage::DirectionType direction;
  const double *                 vtkOrigin = imageData->GetOrigin();
  const double *                 vtkSpacing = imageData->GetSpacing();
  const vtkMatrix3x3 *           vtkDirection = imageData->GetDirectionMatrix();
  for (unsigned int d = 0; d < 3; ++d)
  {
    for (unsigned int e = Dimension; e < 3; ++e)
    {
      if (d != e && (std::abs(vtkDirection->GetElement(static_cast<int>(d), static_cast<int>(e))) > 1e-9 ||
                     std::abs(vtkDirection->GetElement(static_cast<int>(e), static_cast<int>(d))) > 1e-9))
      {
        itkGenericExceptionMacro("edm::ImageDataToImage: the direction matrix of the "
                                 << Dimension << "-D vtkImageData mixes axis " << e
                                 << " with the others: its plane is not z = const.");
      }
    }
  }
  for (unsigned int d = 0; d < Dimension; ++d)
  {
    index[d] = extent[2 * d];
    size[d] = static_cast<itk::SizeValueType>(extent[2 * d + 1] - extent[2 * d] + 1);
    origin[d] = vtkOrigin[d];
    spacing[d] = vtkSpacing[d];
    for (unsigned int e = 0; e < Dimension; ++e)
    {
      direction(d, e) = vtkDirection->GetElement(static_cast<int>(d), static_cast<int>(e));
    }
  }
  auto image = TImage::New();
  image->SetRegions(typename TImage::RegionType(index, size));
  image->SetOrigin(origin);
  image->SetSpacing(spacing);
  image->SetDirection(direction);
  image->Allocate();
  PixelType * buffer = image->GetBufferPointer();
  const auto  numberOfPixels = static_cast<vtkIdType>(image->GetBufferedRegion().GetNumberOfPixels());
  for (vtkIdType i = 0; i < numberOfPixels; ++i)
  {
    for (unsigned int c = 0; c < numberOfComponents; ++c)
    {
      detail::SetComponent(buffer[i], c, detail::ReadValue<ValueType>(array, i, static_cast<int>(c)));
    }
  }
  return image;
}

} // end namespace edm

#endif
