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
#ifndef edmPolyLineCell_h
#define edmPolyLineCell_h

#include "itkExplicitDeformableModelCompatibility.h"
#include "itkPolygonCell.h"
#include "itkVertexCell.h"

namespace edm
{

/** \class PolyLineCell
 * \brief An open chain of two or more points, for ITK versions without
 * itk::PolyLineCell (ITK 5.2 has none).
 *
 * The cell keeps its points in order and reports itself as a LINE_CELL of
 * dimension 1 with any number of points: the vertex-neighbour table of
 * itk::DeformableMeshFilter joins consecutive points of a LINE_CELL, so a
 * polyline contributes the same edges as the chain of its segments. Its
 * boundary features of dimension 0 are its two end points.
 *
 * The storage is the one of itk::PolygonCell (a point identifier vector); the
 * closing edge of a polygon is never reported.
 *
 * \sa MeshToPolyData, PolyDataToMesh
 * \ingroup ExplicitDeformableModelVTK
 */
template <typename TCellInterface>
class PolyLineCell : public itk::PolygonCell<TCellInterface>
{
public:
  ITK_DISALLOW_COPY_AND_MOVE(PolyLineCell);

  // The spelled-out itkCellCommonTypedefs (whose AutoPointer is unqualified).
  using Self = PolyLineCell;
  using ConstSelfAutoPointer = itk::AutoPointer<const Self>;
  using SelfAutoPointer = itk::AutoPointer<Self>;
  using RawPointer = Self *;
  using ConstRawPointer = const Self *;
  itkCellInheritedTypedefs(TCellInterface);

  using VertexType = itk::VertexCell<TCellInterface>;
  using VertexAutoPointer = typename VertexType::SelfAutoPointer;

  /** Standard part of every itk Object. */
  itkOverrideGetNameOfClassMacro(PolyLineCell);

  PolyLineCell() = default;
  ~PolyLineCell() override = default;

  itk::CommonEnums::CellGeometry
  GetType() const override
  {
    return itk::CommonEnums::CellGeometry::LINE_CELL;
  }

  void
  MakeCopy(CellAutoPointer & cellPointer) const override
  {
    auto * copy = new Self;
    copy->SetPointIds(this->PointIdsBegin(), this->PointIdsEnd());
    cellPointer.TakeOwnership(copy);
  }

  unsigned int
  GetDimension() const override
  {
    return 1;
  }

  /** Two end points (dimension 0), nothing else. */
  CellFeatureCount
  GetNumberOfBoundaryFeatures(int dimension) const override
  {
    return (dimension == 0 && this->GetNumberOfPoints() >= 2) ? 2 : 0;
  }

  bool
  GetBoundaryFeature(int dimension, CellFeatureIdentifier featureId, CellAutoPointer & cellPointer) override
  {
    if (dimension != 0 || featureId > 1 || this->GetNumberOfPoints() < 2)
    {
      cellPointer.Reset();
      return false;
    }
    auto * vertex = new VertexType;
    vertex->SetPointId(0, featureId == 0 ? *this->PointIdsBegin() : *(this->PointIdsEnd() - 1));
    cellPointer.TakeOwnership(vertex);
    return true;
  }
};

} // end namespace edm

#endif
