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

// The vectorised step of DeformableMeshFilter held against a scalar reference
// step built on DeformableMeshUpdateRule, on every kernel path; and a 300-step
// run held against the bits the step gave before its kernels were split out.

#include "itkDeformableMeshFilter.h"
#include "itkDeformableMeshUpdateRule.h"
#include "itkImageRegionIteratorWithIndex.h"
#include "itkLineCell.h"
#include "itkPolygonCell.h"
#include "itkRegularSphereMeshSource.h"
#include "itkTriangleCell.h"
#include "itkVectorLinearInterpolateImageFunction.h"
#include "gtest/gtest.h"

#include <cmath>
#include <cstring>
#include <algorithm>
#include <array>
#include <cstdint>
#include <limits>
#include <string>
#include <map>
#include <random>
#include <set>
#include <vector>

namespace
{
using MeshType = itk::Mesh<double, 3, itk::DefaultStaticMeshTraits<double, 3, 3, double, double, double>>;
using ForceImageType = itk::Image<itk::Vector<float, 3>, 3>;
using FilterType = itk::DeformableMeshFilter<MeshType, ForceImageType>;
using RuleType = itk::DeformableMeshUpdateRule;
using VectorType = RuleType::VectorType;
using CellType = MeshType::CellType;
using KernelPath = itk::DeformableMeshFilterDetail::KernelPath;

/** Sets a kernel path for the scope of the object. */
class KernelPathScope
{
public:
  explicit KernelPathScope(KernelPath path)
    : m_Saved(itk::DeformableMeshFilterDetail::GetKernelPath())
  {
    m_Available = itk::DeformableMeshFilterDetail::SetKernelPath(path);
  }
  ~KernelPathScope() { itk::DeformableMeshFilterDetail::SetKernelPath(m_Saved); }
  bool
  Available() const
  {
    return m_Available;
  }

private:
  KernelPath m_Saved;
  bool       m_Available{ false };
};

const KernelPath AllPaths[] = { KernelPath::AVX2FMA, KernelPath::SSE2, KernelPath::Portable };

void
AddCell(MeshType * mesh, CellType * cell, std::initializer_list<MeshType::PointIdentifier> ids)
{
  unsigned int k = 0;
  for (const auto id : ids)
  {
    cell->SetPointId(k++, id);
  }
  CellType::CellAutoPointer pointer;
  pointer.TakeOwnership(cell);
  mesh->SetCell(mesh->GetNumberOfCells(), pointer);
}

MeshType::PointIdentifier
AddPoint(MeshType * mesh, double x, double y, double z)
{
  MeshType::PointType p;
  p[0] = x;
  p[1] = y;
  p[2] = z;
  const auto id = mesh->GetNumberOfPoints();
  mesh->SetPoint(id, p);
  return id;
}

/** A mesh with every kind of vertex the step distinguishes: a closed sphere
 * whose triangles are split at their centroids one in three (valences 3 to
 * 12 mixed, so that the chunks are processed in valence order), its points
 * displaced off the sphere; a disk of 12 triangles (a closed ring of 12 at
 * its centre, open fans on its rim); a quadrilateral; a fin on an edge of the
 * disk (a non-manifold edge); a polyline of two segments; an isolated point. */
MeshType::Pointer
MakeIrregularMesh()
{
  using SourceType = itk::RegularSphereMeshSource<MeshType>;
  auto                   source = SourceType::New();
  SourceType::VectorType scale;
  SourceType::PointType  center;
  scale.Fill(9.0);
  center.Fill(16.0);
  source->SetCenter(center);
  source->SetScale(scale);
  source->SetResolution(4);
  source->Update();
  const MeshType * sphere = source->GetOutput();

  auto mesh = MeshType::New();
  for (MeshType::PointIdentifier i = 0; i < sphere->GetNumberOfPoints(); ++i)
  {
    const auto   p = sphere->GetPoint(i);
    const double wobble = 1.0 + 0.06 * std::sin(1.7 * i) + 0.03 * std::cos(0.37 * i * i);
    AddPoint(mesh, 16.0 + wobble * (p[0] - 16.0), 16.0 + wobble * (p[1] - 16.0), 16.0 + wobble * (p[2] - 16.0));
  }
  unsigned int t = 0;
  for (auto it = sphere->GetCells()->Begin(); it != sphere->GetCells()->End(); ++it, ++t)
  {
    const auto * ids = it.Value()->PointIdsBegin();
    if (t % 3 == 0)
    {
      const auto a = mesh->GetPoint(ids[0]);
      const auto b = mesh->GetPoint(ids[1]);
      const auto c = mesh->GetPoint(ids[2]);
      const auto m = AddPoint(mesh, (a[0] + b[0] + c[0]) / 3, (a[1] + b[1] + c[1]) / 3, (a[2] + b[2] + c[2]) / 3);
      AddCell(mesh, new itk::TriangleCell<CellType>, { ids[0], ids[1], m });
      AddCell(mesh, new itk::TriangleCell<CellType>, { ids[1], ids[2], m });
      AddCell(mesh, new itk::TriangleCell<CellType>, { ids[2], ids[0], m });
    }
    else
    {
      AddCell(mesh, new itk::TriangleCell<CellType>, { ids[0], ids[1], ids[2] });
    }
  }
  // Disk of 12 triangles around (4, 4, 28), slightly curved.
  const auto                             hub = AddPoint(mesh, 4.0, 4.0, 28.0);
  std::vector<MeshType::PointIdentifier> rim;
  for (unsigned int k = 0; k < 12; ++k)
  {
    const double angle = 2.0 * 3.14159265358979 * k / 12.0;
    rim.push_back(AddPoint(mesh, 4.0 + 3.0 * std::cos(angle), 4.0 + 2.5 * std::sin(angle), 27.0 + 0.3 * (k % 3)));
  }
  for (unsigned int k = 0; k < 12; ++k)
  {
    AddCell(mesh, new itk::TriangleCell<CellType>, { hub, rim[k], rim[(k + 1) % 12] });
  }
  // A fin on the rim edge (rim[0], rim[1]): three triangles share it.
  const auto tip = AddPoint(mesh, 7.5, 5.0, 30.0);
  AddCell(mesh, new itk::TriangleCell<CellType>, { rim[1], rim[0], tip });
  // A quadrilateral, a polyline, an isolated point.
  const auto q0 = AddPoint(mesh, 28.0, 2.0, 3.0);
  const auto q1 = AddPoint(mesh, 30.0, 2.5, 3.2);
  const auto q2 = AddPoint(mesh, 30.5, 4.5, 3.0);
  const auto q3 = AddPoint(mesh, 28.2, 4.0, 4.1);
  auto *     quad = new itk::PolygonCell<CellType>(4);
  AddCell(mesh, quad, { q0, q1, q2, q3 });
  const auto l0 = AddPoint(mesh, 3.0, 28.0, 4.0);
  const auto l1 = AddPoint(mesh, 4.0, 29.5, 4.5);
  const auto l2 = AddPoint(mesh, 5.5, 30.0, 4.0);
  AddCell(mesh, new itk::LineCell<CellType>, { l0, l1 });
  AddCell(mesh, new itk::LineCell<CellType>, { l1, l2 });
  AddPoint(mesh, 20.0, 30.0, 2.0);
  return mesh;
}

/** A smooth force field of lengths up to about 1 whose direction turns
 * across the image, on a grid of spacing (1.1, 0.9, 1.0), rotated, so that
 * some vertices of the mesh lie outside it. */
ForceImageType::Pointer
MakeForceImage()
{
  auto                     image = ForceImageType::New();
  ForceImageType::SizeType size;
  size[0] = 28;
  size[1] = 34;
  size[2] = 31;
  image->SetRegions(size);
  ForceImageType::SpacingType spacing;
  spacing[0] = 1.1;
  spacing[1] = 0.9;
  spacing[2] = 1.0;
  image->SetSpacing(spacing);
  ForceImageType::PointType origin;
  origin[0] = 0.5;
  origin[1] = -1.0;
  origin[2] = 0.8;
  image->SetOrigin(origin);
  ForceImageType::DirectionType direction;
  const double                  c = std::cos(0.2);
  const double                  s = std::sin(0.2);
  direction.SetIdentity();
  direction(0, 0) = c;
  direction(0, 1) = -s;
  direction(1, 0) = s;
  direction(1, 1) = c;
  image->SetDirection(direction);
  image->Allocate();
  for (itk::ImageRegionIteratorWithIndex<ForceImageType> it(image, image->GetBufferedRegion()); !it.IsAtEnd(); ++it)
  {
    ForceImageType::PointType p;
    image->TransformIndexToPhysicalPoint(it.GetIndex(), p);
    ForceImageType::PixelType f;
    f[0] = static_cast<float>(0.6 * std::sin(0.31 * p[1] + 0.2) + 0.3 * (16.0 - p[0]) / 16.0);
    f[1] = static_cast<float>(0.6 * std::cos(0.23 * p[2] - 0.4) + 0.3 * (16.0 - p[1]) / 16.0);
    f[2] = static_cast<float>(0.5 * std::sin(0.17 * p[0] + 0.29 * p[1]) + 0.3 * (16.0 - p[2]) / 16.0);
    it.Set(f);
  }
  return image;
}

struct TermSet
{
  const char * name;
  double       scaleFactor;
  double       elasticity;
  bool         tangential;
  double       rigidity;
  double       balloon;
  double       maximumStep;
  double       referenceEdgeLength; // mm; 0: none (the weights of the mesh's own edges)
};

/** The scalar reference step: the mesh's neighbours and triangles read from
 * its cells, the force by ITK's linear interpolation, each vertex's
 * displacement by DeformableMeshUpdateRule; with a reference edge length, the
 * edge weight from the mean over the vertices that have neighbours of their
 * edges' mean squared length at the start of the iteration, and as many
 * sub-steps as the rule says, the external force and the balloon in the
 * last. */
class ReferenceStep
{
public:
  ReferenceStep(const MeshType * mesh, const ForceImageType * forces, const TermSet & terms)
    : m_Forces(forces)
    , m_Terms(terms)
  {
    const auto n = mesh->GetNumberOfPoints();
    m_Neighbours.resize(n);
    m_Triangles.resize(n);
    for (MeshType::PointIdentifier i = 0; i < n; ++i)
    {
      const auto p = mesh->GetPoint(i);
      m_X.push_back(VectorType(p.GetDataPointer()));
    }
    std::vector<std::array<MeshType::PointIdentifier, 3>> triangles;
    for (auto it = mesh->GetCells()->Begin(); it != mesh->GetCells()->End(); ++it)
    {
      const auto * cell = it.Value();
      const auto * ids = cell->PointIdsBegin();
      const auto   count = cell->GetNumberOfPoints();
      if (cell->GetType() == itk::CommonEnums::CellGeometry::LINE_CELL)
      {
        Connect(ids[0], ids[1]);
        continue;
      }
      for (unsigned int k = 0; k < count; ++k)
      {
        Connect(ids[k], ids[(k + 1) % count]);
      }
      for (unsigned int k = 1; k + 1 < count; ++k)
      {
        triangles.push_back({ ids[0], ids[k], ids[k + 1] });
      }
    }
    double volume = 0.0;
    for (const auto & t : triangles)
    {
      volume += m_X[t[0]] * CrossProduct(m_X[t[1]], m_X[t[2]]);
      for (unsigned int k = 0; k < 3; ++k)
      {
        m_Triangles[t[k]].push_back({ t[(k + 1) % 3], t[(k + 2) % 3] });
      }
    }
    m_Sign = volume < 0.0 ? -1.0 : 1.0;
    m_Released.assign(n, false);
    m_Interpolator->SetInputImage(forces);
  }

  /** One iteration; returns its number of sub-steps. */
  double
  Step()
  {
    double weight = 0.0;
    if (m_Terms.referenceEdgeLength > 0.0)
    {
      double      sum = 0.0;
      std::size_t connected = 0;
      for (std::size_t i = 0; i < m_X.size(); ++i)
      {
        if (m_Neighbours[i].empty())
        {
          continue;
        }
        double squares = 0.0;
        for (const auto j : m_Neighbours[i])
        {
          squares += (m_X[j] - m_X[i]).GetSquaredNorm();
        }
        sum += squares / static_cast<double>(m_Neighbours[i].size());
        ++connected;
      }
      weight = RuleType::EdgeWeight(m_Terms.referenceEdgeLength, sum / static_cast<double>(connected));
    }
    const RuleType rule = RuleType::FromParameters(m_Terms.scaleFactor,
                                                   m_Terms.elasticity,
                                                   m_Terms.rigidity,
                                                   m_Terms.tangential,
                                                   m_Terms.balloon,
                                                   m_Terms.maximumStep,
                                                   weight);
    for (double k = 1.0; k < rule.subSteps; k += 1.0)
    {
      SubStep(rule.InternalOnly());
    }
    SubStep(rule);
    return rule.subSteps;
  }

  void
  SubStep(const RuleType & rule)
  {
    const std::size_t       n = m_X.size();
    std::vector<VectorType> umbrella(n);
    std::vector<VectorType> normal(n);
    for (std::size_t i = 0; i < n; ++i)
    {
      umbrella[i] = Umbrella(m_X, i);
      VectorType sum(0.0);
      for (const auto & pair : m_Triangles[i])
      {
        sum += CrossProduct(m_X[pair[0]] - m_X[i], m_X[pair[1]] - m_X[i]);
      }
      normal[i] = sum.GetNorm() > 0.0 ? m_Sign * sum / sum.GetNorm() : VectorType(0.0);
    }
    std::vector<VectorType> next(n);
    for (std::size_t i = 0; i < n; ++i)
    {
      RuleType::VertexTerms v;
      v.force = Force(m_X[i]);
      v.umbrella = umbrella[i];
      v.normal = normal[i];
      v.umbrellaMean = Umbrella(umbrella, i) + umbrella[i];
      bool released = m_Released[i];
      next[i] = m_X[i] + rule.Displacement(v, released);
      m_Released[i] = released;
    }
    m_X = next;
  }

  const std::vector<VectorType> &
  GetCoordinates() const
  {
    return m_X;
  }

private:
  static VectorType
  CrossProduct(const VectorType & a, const VectorType & b)
  {
    VectorType c;
    c[0] = a[1] * b[2] - a[2] * b[1];
    c[1] = a[2] * b[0] - a[0] * b[2];
    c[2] = a[0] * b[1] - a[1] * b[0];
    return c;
  }

  void
  Connect(MeshType::PointIdentifier a, MeshType::PointIdentifier b)
  {
    if (a != b)
    {
      m_Neighbours[a].insert(b);
      m_Neighbours[b].insert(a);
    }
  }

  /** Mean of field over the neighbours of i, minus field[i]; 0 without
   * neighbours. */
  VectorType
  Umbrella(const std::vector<VectorType> & field, std::size_t i) const
  {
    if (m_Neighbours[i].empty())
    {
      return VectorType(0.0);
    }
    VectorType sum(0.0);
    for (const auto j : m_Neighbours[i])
    {
      sum += field[j];
    }
    return sum / static_cast<double>(m_Neighbours[i].size()) - field[i];
  }

  VectorType
  Force(const VectorType & x) const
  {
    ForceImageType::PointType p;
    for (unsigned int d = 0; d < 3; ++d)
    {
      p[d] = x[d];
    }
    if (!m_Interpolator->IsInsideBuffer(p))
    {
      return VectorType(0.0);
    }
    const auto f = m_Interpolator->Evaluate(p);
    VectorType v;
    for (unsigned int d = 0; d < 3; ++d)
    {
      v[d] = f[d];
    }
    return v;
  }

  using InterpolatorType = itk::VectorLinearInterpolateImageFunction<ForceImageType, double>;
  const ForceImageType *                                             m_Forces;
  TermSet                                                            m_Terms;
  std::vector<VectorType>                                            m_X;
  std::vector<std::set<MeshType::PointIdentifier>>                   m_Neighbours;
  std::vector<std::vector<std::array<MeshType::PointIdentifier, 2>>> m_Triangles;
  std::vector<bool>                                                  m_Released;
  double                                                             m_Sign{ 1.0 };
  InterpolatorType::Pointer                                          m_Interpolator{ InterpolatorType::New() };
};

// Each term alone, then together; Elasticity + 2 Rigidity above 1 once
// (scaled); then with reference edge lengths (the irregular mesh's root mean
// square edge length is about 1.1 mm): below it (weights below 1, one step),
// and above it (several sub-steps). Not much above it with every term: the
// elasticity shrinks the quadrilateral to a point within the 6 iterations,
// whose normal is then the rounding of its triangles (single precision in the
// kernels, double in the reference).
const TermSet TermSets[] = {
  { "external force only", 0.7, 0.0, true, 0.0, 0.0, 0.0, 0.0 },
  { "elasticity, full umbrella", 0.5, 0.4, false, 0.0, 0.0, 0.0, 0.0 },
  { "elasticity, tangential", 0.5, 0.4, true, 0.0, 0.0, 0.0, 0.0 },
  { "rigidity", 0.5, 0.0, true, 0.3, 0.0, 0.0, 0.0 },
  { "balloon and its release", 0.6, 0.0, true, 0.0, 0.35, 0.0, 0.0 },
  { "step bound", 0.9, 0.0, true, 0.0, 0.0, 0.25, 0.0 },
  { "all terms", 0.6, 0.3, true, 0.2, 0.3, 0.4, 0.0 },
  { "all terms, a + 2b above 1", 0.6, 0.8, false, 0.4, -0.2, 0.5, 0.0 },
  { "all terms, reference edge length 0.8 mm", 0.6, 0.5, true, 0.3, 0.3, 0.0, 0.8 },
  { "full umbrella, reference edge length 3 mm (sub-steps)", 0.5, 0.4, false, 0.0, 0.0, 0.0, 3.0 },
  { "all terms, reference edge length 1.4 mm (sub-steps)", 0.6, 0.2, true, 0.15, 0.2, 0.4, 1.4 },
};

std::vector<VectorType>
RunFilter(const MeshType *       mesh,
          const ForceImageType * forces,
          const TermSet &        terms,
          unsigned int           steps,
          unsigned int *         subSteps = nullptr)
{
  auto filter = FilterType::New();
  filter->SetInput(mesh);
  filter->SetForceImage(forces);
  filter->SetScaleFactor(terms.scaleFactor);
  filter->SetElasticity(terms.elasticity);
  filter->SetTangentialElasticity(terms.tangential);
  filter->SetRigidity(terms.rigidity);
  filter->SetBalloon(terms.balloon);
  filter->SetMaximumStepLength(terms.maximumStep);
  filter->SetReferenceEdgeLength(terms.referenceEdgeLength);
  filter->SetNumberOfIterations(steps);
  filter->Update();
  if (subSteps != nullptr)
  {
    *subSteps = filter->GetNumberOfSubSteps();
  }
  std::vector<VectorType> x;
  for (auto it = filter->GetOutput()->GetPoints()->Begin(); it != filter->GetOutput()->GetPoints()->End(); ++it)
  {
    x.push_back(VectorType(it.Value().GetDataPointer()));
  }
  return x;
}
} // namespace

// The kernels against the scalar rule, one term set at a time, on each kernel
// path: 6 iterations, so that released balloons and moved neighbours carry
// over. The tolerance covers the single-precision umbrella vectors and
// normals of the geometry pass (relative 6e-8) and the order of the sums;
// an error in any one term of the kernels moves vertices by 1e-3 mm or more.
TEST(DeformableMeshFilterKernels, KernelsFollowTheScalarRuleOnIrregularMeshes)
{
  const auto mesh = MakeIrregularMesh();
  const auto forces = MakeForceImage();
  ASSERT_GT(mesh->GetNumberOfPoints(), 2 * itk::DeformableMeshFilterDetail::BlockSize);
  constexpr unsigned int steps = 6;
  for (const TermSet & terms : TermSets)
  {
    ReferenceStep reference(mesh, forces, terms);
    double        lastSubSteps = 0.0;
    double        mostSubSteps = 0.0;
    for (unsigned int k = 0; k < steps; ++k)
    {
      lastSubSteps = reference.Step();
      mostSubSteps = std::max(mostSubSteps, lastSubSteps);
    }
    // The cases of several sub-steps have them.
    EXPECT_EQ(mostSubSteps > 1.0, std::strstr(terms.name, "sub-steps") != nullptr) << terms.name;
    for (const KernelPath path : AllPaths)
    {
      const KernelPathScope scope(path);
      if (!scope.Available())
      {
        continue;
      }
      unsigned int subSteps = 0;
      const auto   x = RunFilter(mesh, forces, terms, steps, &subSteps);
      ASSERT_EQ(x.size(), reference.GetCoordinates().size());
      EXPECT_EQ(subSteps, lastSubSteps) << terms.name;
      double largest = 0.0;
      double moved = 0.0;
      for (std::size_t i = 0; i < x.size(); ++i)
      {
        largest = std::max(largest, (x[i] - reference.GetCoordinates()[i]).GetNorm());
        moved = std::max(moved, (x[i] - VectorType(mesh->GetPoint(i).GetDataPointer())).GetNorm());
      }
      EXPECT_LT(largest, 1e-5) << terms.name << ", " << itk::DeformableMeshFilterDetail::KernelPathName(path);
      EXPECT_GT(moved, 0.5) << terms.name;
    }
  }
}

namespace
{
// BEGIN 300-STEP CASE (the same code ran on the step before its kernels were
// split out, commit 1d1a4ed, to give the bits below)
/** Inputs whose values do not depend on the compile flags (no operation
 * that a fused multiply-add could change): an octahedron of lattice points
 * |i| + |j| + |k| = 16, half a millimetre apart, one triangle in four split
 * at its centroid (mixed valences); a force field of exact values pulling
 * the surface onto the sphere of radius 10 voxels about voxel (16, 16, 16). */
MeshType::Pointer
MakeOctahedronMesh()
{
  constexpr int                                           n = 16;
  auto                                                    mesh = MeshType::New();
  std::map<std::array<int, 3>, MeshType::PointIdentifier> ids;
  auto                                                    vertex = [&](int i, int j, int k) {
    const std::array<int, 3> key{ i, j, k };
    const auto               found = ids.find(key);
    if (found != ids.end())
    {
      return found->second;
    }
    const auto id = AddPoint(mesh, 16.0 + 0.5 * i, 16.0 + 0.5 * j, 16.0 + 0.5 * k);
    ids[key] = id;
    return id;
  };
  unsigned int t = 0;
  for (int sz = -1; sz <= 1; sz += 2)
  {
    for (int sy = -1; sy <= 1; sy += 2)
    {
      for (int sx = -1; sx <= 1; sx += 2)
      {
        const bool flip = sx * sy * sz < 0;
        auto       add = [&](int a0, int b0, int a1, int b1, int a2, int b2) {
          const auto p = vertex(sx * a0, sy * b0, sz * (n - a0 - b0));
          auto       q = vertex(sx * a1, sy * b1, sz * (n - a1 - b1));
          auto       r = vertex(sx * a2, sy * b2, sz * (n - a2 - b2));
          if (flip)
          {
            std::swap(q, r);
          }
          if (t++ % 4 == 0)
          {
            const auto a = mesh->GetPoint(p);
            const auto b = mesh->GetPoint(q);
            const auto c = mesh->GetPoint(r);
            const auto m =
              AddPoint(mesh, (a[0] + b[0] + c[0]) / 3.0, (a[1] + b[1] + c[1]) / 3.0, (a[2] + b[2] + c[2]) / 3.0);
            AddCell(mesh, new itk::TriangleCell<CellType>, { p, q, m });
            AddCell(mesh, new itk::TriangleCell<CellType>, { q, r, m });
            AddCell(mesh, new itk::TriangleCell<CellType>, { r, p, m });
          }
          else
          {
            AddCell(mesh, new itk::TriangleCell<CellType>, { p, q, r });
          }
        };
        for (int a = 0; a < n; ++a)
        {
          for (int b = 0; a + b < n; ++b)
          {
            add(a, b, a + 1, b, a, b + 1);
            if (a + b + 2 <= n)
            {
              add(a + 1, b, a + 1, b + 1, a, b + 1);
            }
          }
        }
      }
    }
  }
  return mesh;
}

ForceImageType::Pointer
MakeExactForceImage()
{
  auto                     image = ForceImageType::New();
  ForceImageType::SizeType size;
  size.Fill(33);
  image->SetRegions(size);
  image->Allocate();
  for (itk::ImageRegionIteratorWithIndex<ForceImageType> it(image, image->GetBufferedRegion()); !it.IsAtEnd(); ++it)
  {
    const auto                index = it.GetIndex();
    const int                 e[3] = { static_cast<int>(index[0]) - 16,
                                       static_cast<int>(index[1]) - 16,
                                       static_cast<int>(index[2]) - 16 };
    const int                 q = std::max(-512, std::min(512, 100 - (e[0] * e[0] + e[1] * e[1] + e[2] * e[2])));
    ForceImageType::PixelType f;
    for (unsigned int d = 0; d < 3; ++d)
    {
      f[d] = static_cast<float>(e[d] * q) / 4096.0f;
    }
    it.Set(f);
  }
  return image;
}

/** FNV-1a hash of the bytes of the coordinates. */
uint64_t
HashOf(const std::vector<VectorType> & x)
{
  uint64_t hash = 14695981039346656037ULL;
  for (const auto & v : x)
  {
    for (unsigned int d = 0; d < 3; ++d)
    {
      unsigned char bytes[sizeof(double)];
      std::memcpy(bytes, &v[d], sizeof(double));
      for (const unsigned char b : bytes)
      {
        hash = (hash ^ b) * 1099511628211ULL;
      }
    }
  }
  return hash;
}

const TermSet LongRunTerms[] = {
  { "all terms", 0.5, 0.3, true, 0.1, 0.15, 0.4, 0.0 },
  { "full umbrella and balloon", 0.5, 0.25, false, 0.0, 0.1, 0.0, 0.0 },
};
// END 300-STEP CASE
} // namespace

// 300 iterations on each kernel path, against the bits of the step before
// its kernels were split out (commit 1d1a4ed). The AVX2 path gives the bits
// of that step built with -march=native; the SSE2 and portable paths those of
// its SSE2 build, when this test is built without FMA (with FMA the compiler
// may fuse their products and sums: they are then held to rounding against
// the AVX2 path).
TEST(DeformableMeshFilterKernels, ThreeHundredStepsGiveTheBitsOfTheStepBeforeTheSplit)
{
  const auto     mesh = MakeOctahedronMesh();
  const auto     forces = MakeExactForceImage();
  const uint64_t fusedBits[] = { 0xcf96661356413ad0ULL, 0x0385b4972fae6c80ULL };   // former -march=native build
  const uint64_t unfusedBits[] = { 0xf51b8c511935e6e8ULL, 0x21b1535ae0f3ed91ULL }; // former SSE2 build
  for (unsigned int c = 0; c < 2; ++c)
  {
    const TermSet &         terms = LongRunTerms[c];
    std::vector<VectorType> fused;
    for (const KernelPath path : AllPaths)
    {
      const KernelPathScope scope(path);
      if (!scope.Available())
      {
        continue;
      }
      const auto x = RunFilter(mesh, forces, terms, 300);
      if (path == KernelPath::AVX2FMA)
      {
        EXPECT_EQ(HashOf(x), fusedBits[c]) << terms.name;
        fused = x;
        continue;
      }
#if defined(__FMA__)
      for (std::size_t i = 0; i < x.size() && !fused.empty(); ++i)
      {
        EXPECT_LT((x[i] - fused[i]).GetNorm(), 1e-6) << terms.name << ", vertex " << i;
      }
#else
      EXPECT_EQ(HashOf(x), unfusedBits[c])
        << terms.name << ", " << itk::DeformableMeshFilterDetail::KernelPathName(path);
#endif
    }
  }
}

// ReferenceEdgeLength: bad values are refused by name; a reference length
// that would need more sub-steps than allowed stops the update with an
// exception that says how many and why, rather than running for hours.
TEST(DeformableMeshFilterKernels, ReferenceEdgeLengthBadInputAndSubStepLimit)
{
  const auto mesh = MakeIrregularMesh();
  const auto forces = MakeForceImage();
  auto       filter = FilterType::New();
  filter->SetInput(mesh);
  filter->SetForceImage(forces);
  filter->SetElasticity(0.3);
  filter->SetRigidity(0.1);
  filter->SetNumberOfIterations(2);
  for (const double bad : { -1.0, std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::infinity() })
  {
    filter->SetReferenceEdgeLength(bad);
    try
    {
      filter->Update();
      ADD_FAILURE() << "ReferenceEdgeLength " << bad << " accepted";
    }
    catch (const itk::ExceptionObject & e)
    {
      EXPECT_NE(std::string(e.GetDescription()).find("ReferenceEdgeLength must be finite and non-negative"),
                std::string::npos)
        << e.GetDescription();
    }
  }
  // Root mean square edge about 1.1 mm: L = 20 mm gives w of about 330 and
  // 2 b w^2 of about 22 000 sub-steps.
  filter->SetReferenceEdgeLength(20.0);
  filter->SetMaximumNumberOfSubSteps(500);
  try
  {
    filter->Update();
    ADD_FAILURE() << "an iteration of more sub-steps than MaximumNumberOfSubSteps ran";
  }
  catch (const itk::ExceptionObject & e)
  {
    EXPECT_NE(std::string(e.GetDescription()).find("more than MaximumNumberOfSubSteps (500)"), std::string::npos)
      << e.GetDescription();
  }
  // The same reference length with the weights it needs runs, in sub-steps.
  filter->SetElasticity(0.0);
  filter->SetRigidity(0.0001);
  filter->Update();
  EXPECT_GT(filter->GetNumberOfSubSteps(), 1u);
  EXPECT_LE(filter->GetNumberOfSubSteps(), 500u);
  EXPECT_GT(filter->GetEdgeWeight(), 100.0);
}

// With sub-steps the diagnostics and the convergence measure are those of
// the whole iteration: each vertex's displacement from where the iteration
// started, not that of its last sub-step.
TEST(DeformableMeshFilterKernels, SubStepsReportTheWholeIterationsDisplacement)
{
  const auto    mesh = MakeIrregularMesh();
  const auto    forces = MakeForceImage();
  const TermSet terms = { "sub-steps", 0.6, 0.2, true, 0.15, 0.2, 0.4, 1.4 };
  auto          run = [&](unsigned int steps) {
    auto filter = FilterType::New();
    filter->SetInput(mesh);
    filter->SetForceImage(forces);
    filter->SetScaleFactor(terms.scaleFactor);
    filter->SetElasticity(terms.elasticity);
    filter->SetRigidity(terms.rigidity);
    filter->SetBalloon(terms.balloon);
    filter->SetMaximumStepLength(terms.maximumStep);
    filter->SetReferenceEdgeLength(terms.referenceEdgeLength);
    filter->SetNumberOfIterations(steps);
    filter->Update();
    return filter;
  };
  const auto before = run(2);
  const auto after = run(3);
  ASSERT_GT(after->GetNumberOfSubSteps(), 1u);
  const auto & displacements = after->GetDisplacementMagnitudes();
  ASSERT_EQ(displacements.size(), mesh->GetNumberOfPoints());
  double largest = 0.0;
  for (MeshType::PointIdentifier i = 0; i < mesh->GetNumberOfPoints(); ++i)
  {
    const double moved = after->GetOutput()->GetPoint(i).EuclideanDistanceTo(before->GetOutput()->GetPoint(i));
    EXPECT_NEAR(displacements[i], moved, 1e-6 + 1e-6 * moved) << i;
    largest = std::max(largest, moved);
  }
  EXPECT_DOUBLE_EQ(after->GetLastMaximumDisplacement(), largest);
  EXPECT_GT(largest, 0.1);
}

// SuppressTangentialDrift's weight skips its square root and division for
// squares up to DriftWeightless(): there the formula's weight is 0 too, for
// thresholds of every magnitude and mantissa, at the bound and the 64 squares
// below it. Above the threshold's own square the weight is the formula's; the
// bound is below that square.
TEST(DeformableMeshFilterKernels, TheDriftWeightsShortcutIsTheFormulasZero)
{
  namespace Kernel = itk::DeformableMeshFilterDetail::Portable;
  const auto formula = [](double squared, double threshold) {
    return std::max(0.0, std::sqrt(squared) / threshold - 1.0);
  };
  std::mt19937_64                        random(15);
  std::uniform_real_distribution<double> mantissa(1.0, 2.0);
  std::uniform_int_distribution<int>     exponent(-400, 400);
  unsigned int                           weighted = 0;
  for (unsigned int k = 0; k < 20000; ++k)
  {
    const double threshold = std::ldexp(mantissa(random), exponent(random));
    const double weightless = Kernel::DriftWeightless(threshold);
    const double square = threshold * threshold;
    if (square < std::numeric_limits<double>::min())
    {
      EXPECT_EQ(weightless, 0.0) << threshold; // only a zero square skips
      continue;
    }
    if (!std::isfinite(square))
    {
      // The threshold above the square root of every double: the formula's
      // weight is 0 for the largest square.
      EXPECT_EQ(formula(std::numeric_limits<double>::max(), threshold), 0.0) << threshold;
      EXPECT_EQ(Kernel::DriftWeight(std::numeric_limits<double>::max(), threshold, weightless), 0.0);
      continue;
    }
    ASSERT_GT(weightless, 0.0) << threshold;
    ASSERT_LT(weightless, square) << threshold;
    double squared = weightless;
    for (unsigned int step = 0; step < 64; ++step)
    {
      ASSERT_EQ(formula(squared, threshold), 0.0) << threshold << " " << squared;
      ASSERT_EQ(Kernel::DriftWeight(squared, threshold, weightless), 0.0);
      squared = std::nextafter(squared, 0.0);
    }
    // Just above the threshold: the formula's small positive weights.
    squared = square * (1.0 + 1e-9);
    const double weight = Kernel::DriftWeight(squared, threshold, weightless);
    ASSERT_EQ(weight, formula(squared, threshold)) << threshold;
    weighted += weight > 0.0;
  }
  EXPECT_GT(weighted, 15000u);
}

// The reset's sort of edge keys (a counting sort on the smaller point) gives
// std::sort's order: keys of a random mesh-like set with repeats, a point
// with 40 keys (sorted with std::sort in its bucket), an empty set, and keys
// beyond the points (std::sort itself).
TEST(DeformableMeshFilterKernels, EdgeKeysSortAsStdSortDoes)
{
  using itk::DeformableMeshFilterDetail::SortEdgeKeys;
  std::mt19937_64                         random(3);
  constexpr uint64_t                      points = 5000;
  std::uniform_int_distribution<uint64_t> point(0, points - 1);
  std::vector<uint64_t>                   keys;
  for (unsigned int k = 0; k < 30000; ++k)
  {
    const uint64_t a = point(random);
    const uint64_t b = point(random);
    const uint64_t key = std::min(a, b) << 32 | std::max(a, b);
    keys.push_back(key);
    if (k % 2 == 0)
    {
      keys.push_back(key); // an edge of two triangles
    }
  }
  for (uint64_t b = 0; b < 40; ++b)
  {
    keys.push_back(uint64_t{ 17 } << 32 | (4999 - 3 * b));
  }
  std::vector<uint64_t> expected = keys;
  std::sort(expected.begin(), expected.end());
  SortEdgeKeys(keys, points);
  EXPECT_EQ(keys, expected);

  std::vector<uint64_t> none;
  SortEdgeKeys(none, points);
  EXPECT_TRUE(none.empty());

  std::vector<uint64_t> beyond = { uint64_t{ 9 } << 32 | 12, uint64_t{ 3 } << 32 | 4, uint64_t{ 7 } << 32 | 8 };
  SortEdgeKeys(beyond, 8);
  EXPECT_EQ(beyond,
            (std::vector<uint64_t>{ uint64_t{ 3 } << 32 | 4, uint64_t{ 7 } << 32 | 8, uint64_t{ 9 } << 32 | 12 }));
}
