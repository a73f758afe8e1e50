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

// 'edmodel segment' on a 2-D image: the same pipeline as in 3-D
// (ExternalForceImageFilter -> DeformableMeshFilter, region force estimated
// inside the initial contour, coarse to fine) on a contour. The contours
// are read and written here (.csv, .vtk, .vtp) and drawn over the image in
// a PNG. No deformation maths here: the filters do it.

#include "edmodelIO.h"
#include "edmodelOptions.h"
#include "edmodelProgress.h"
#include "edmodelSchedule.h"

#include "itkDeformableMeshFilter.h"
#include "itkExternalForceImageFilter.h"
#include "itkImageFileWriter.h"
#include "itkLineCell.h"
#include "itkPolygonCell.h"
#include "itkRGBPixel.h"
#include "itkSampledGaussianSmoothing.h"

#ifdef EDM_HAVE_VTK
#  include "vtkCellArray.h"
#  include "vtkNew.h"
#  include "vtkPoints.h"
#  include "vtkPolyData.h"
#  include "vtkXMLPolyDataWriter.h"
#endif

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iomanip>
#include <map>
#include <memory>
#include <set>
#include <sstream>
#include <vector>

namespace edm
{
namespace
{

namespace fs = std::filesystem;

using Force2DFilterType = itk::ExternalForceImageFilter<Image2DType, Force2DType>;
using ContourFilterType = itk::DeformableMeshFilter<ContourMeshType, Force2DType>;
using Point2 = ContourMeshType::PointType;

/** One contour: its points in order, closed (the last joins the first) or
 * open. */
struct Contour
{
  std::vector<Point2> points;
  bool                closed{ true };
};
using Contours = std::vector<Contour>;

std::string
Quote(const std::string & path)
{
  return "'" + path + "'";
}

Point2
MakePoint(double x, double y)
{
  Point2 p;
  p[0] = x;
  p[1] = y;
  return p;
}

// --- Contours ---------------------------------------------------------------

size_t
CountPoints(const Contours & contours)
{
  size_t n = 0;
  for (const auto & c : contours)
  {
    n += c.points.size();
  }
  return n;
}

size_t
CountEdges(const Contour & c)
{
  return c.closed ? c.points.size() : c.points.size() - 1;
}

double
Length(const Contour & c)
{
  double length = 0.0;
  for (size_t k = 0; k < CountEdges(c); ++k)
  {
    length += c.points[k].EuclideanDistanceTo(c.points[(k + 1) % c.points.size()]);
  }
  return length;
}

double
MeanEdgeLength(const Contours & contours)
{
  double length = 0.0;
  size_t edges = 0;
  for (const auto & c : contours)
  {
    length += Length(c);
    edges += CountEdges(c);
  }
  return edges > 0 ? length / static_cast<double>(edges) : 0.0;
}

/** Area enclosed by a closed contour (absolute value), physical units. */
double
Area(const Contour & c)
{
  double twice = 0.0;
  for (size_t k = 0; k < c.points.size(); ++k)
  {
    const auto & a = c.points[k];
    const auto & b = c.points[(k + 1) % c.points.size()];
    twice += a[0] * b[1] - a[1] * b[0];
  }
  return 0.5 * std::abs(twice);
}

/** Each edge split at its midpoint (the ends of open contours kept). */
Contours
Subdivide(const Contours & contours)
{
  Contours result;
  for (const auto & c : contours)
  {
    Contour fine;
    fine.closed = c.closed;
    for (size_t k = 0; k < c.points.size(); ++k)
    {
      fine.points.push_back(c.points[k]);
      if (k < CountEdges(c))
      {
        const auto & a = c.points[k];
        const auto & b = c.points[(k + 1) % c.points.size()];
        fine.points.push_back(MakePoint(0.5 * (a[0] + b[0]), 0.5 * (a[1] + b[1])));
      }
    }
    result.push_back(fine);
  }
  return result;
}

double
LongestEdge(const Contours & contours)
{
  double longest = 0.0;
  for (const auto & c : contours)
  {
    for (size_t k = 0; k < CountEdges(c); ++k)
    {
      longest = std::max(longest, c.points[k].EuclideanDistanceTo(c.points[(k + 1) % c.points.size()]));
    }
  }
  return longest;
}

/** Twice the signed area of a closed contour (counter-clockwise positive in
 * a right-handed x, y frame). */
double
TwiceSignedArea(const std::vector<Point2> & points)
{
  double twice = 0.0;
  for (size_t k = 0; k < points.size(); ++k)
  {
    const auto & a = points[k];
    const auto & b = points[(k + 1) % points.size()];
    twice += a[0] * b[1] - a[1] * b[0];
  }
  return twice;
}

/** A crossing of two edges of closed contour \a c that share no point: the
 * edges (k, k + 1) and (m, m + 1), k < m, and where they cross. Edges are
 * swept in order of their smallest x (so O(n log n) plus the pairs whose
 * x ranges overlap); a touching (collinear overlap, an end on the other edge)
 * counts as a crossing. False when there is none. */
bool
FindCrossing(const Contour & c, size_t & firstEdge, size_t & secondEdge, Point2 & where)
{
  const size_t n = c.points.size();
  if (!c.closed || n < 4)
  {
    return false;
  }
  struct Edge
  {
    double lowX;
    double highX;
    size_t index;
  };
  std::vector<Edge> edges(n);
  for (size_t k = 0; k < n; ++k)
  {
    const auto & a = c.points[k];
    const auto & b = c.points[(k + 1) % n];
    edges[k] = { std::min(a[0], b[0]), std::max(a[0], b[0]), k };
  }
  std::sort(edges.begin(), edges.end(), [](const Edge & a, const Edge & b) { return a.lowX < b.lowX; });
  const auto cross = [](const Point2 & o, const Point2 & a, const Point2 & b) {
    return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0]);
  };
  bool   found = false;
  size_t bestFirst = 0;
  size_t bestSecond = 0;
  for (size_t i = 0; i < n; ++i)
  {
    for (size_t j = i + 1; j < n && edges[j].lowX <= edges[i].highX; ++j)
    {
      size_t k = edges[i].index;
      size_t m = edges[j].index;
      if (k > m)
      {
        std::swap(k, m);
      }
      // Neighbouring edges share a point.
      if (m == k + 1 || (k == 0 && m == n - 1))
      {
        continue;
      }
      const Point2 & a = c.points[k];
      const Point2 & b = c.points[(k + 1) % n];
      const Point2 & p = c.points[m];
      const Point2 & q = c.points[(m + 1) % n];
      if (std::max(p[1], q[1]) < std::min(a[1], b[1]) || std::max(a[1], b[1]) < std::min(p[1], q[1]))
      {
        continue;
      }
      const double d1 = cross(a, b, p);
      const double d2 = cross(a, b, q);
      const double d3 = cross(p, q, a);
      const double d4 = cross(p, q, b);
      if (!((d1 <= 0.0 && d2 >= 0.0) || (d1 >= 0.0 && d2 <= 0.0)) ||
          !((d3 <= 0.0 && d4 >= 0.0) || (d3 >= 0.0 && d4 <= 0.0)))
      {
        continue;
      }
      // The first crossing along the contour: the smallest first edge, then
      // the smallest second one (the same pair whatever the sweep's order).
      if (!found || k < bestFirst || (k == bestFirst && m < bestSecond))
      {
        found = true;
        bestFirst = k;
        bestSecond = m;
        const double denominator = d1 - d2;
        const double t = denominator != 0.0 ? d1 / denominator : 0.5;
        where = MakePoint(p[0] + t * (q[0] - p[0]), p[1] + t * (q[1] - p[1]));
      }
    }
  }
  firstEdge = bestFirst;
  secondEdge = bestSecond;
  return found;
}

/** The closed contours without their loops: at a crossing of two of its
 * edges a contour is two loops joined at the crossing; the one kept turns
 * the way the whole contour turns (the sign of its area) and encloses the
 * larger area that way, the other (a fold, or the inside of an obstacle the
 * contour grew around and closed behind) is dropped; repeated until no two
 * edges cross. A loop of fewer than 3 points is dropped whole. Open
 * contours are left as they are. Returns the number of loops removed. */
size_t
RemoveLoops(Contours & contours)
{
  size_t removed = 0;
  for (auto & c : contours)
  {
    if (!c.closed)
    {
      continue;
    }
    const double orientation = TwiceSignedArea(c.points) >= 0.0 ? 1.0 : -1.0;
    size_t       k = 0;
    size_t       m = 0;
    Point2       where;
    while (FindCrossing(c, k, m, where))
    {
      // Loop A: the crossing, then points k + 1 .. m; loop B: the crossing,
      // then points m + 1 .. n - 1, 0 .. k.
      const size_t        n = c.points.size();
      std::vector<Point2> a{ where };
      a.insert(a.end(),
               c.points.begin() + static_cast<std::ptrdiff_t>(k + 1),
               c.points.begin() + static_cast<std::ptrdiff_t>(m + 1));
      std::vector<Point2> b{ where };
      b.insert(b.end(), c.points.begin() + static_cast<std::ptrdiff_t>(m + 1), c.points.end());
      b.insert(b.end(), c.points.begin(), c.points.begin() + static_cast<std::ptrdiff_t>(k + 1));
      const double areaA = orientation * TwiceSignedArea(a);
      const double areaB = orientation * TwiceSignedArea(b);
      c.points = (a.size() >= 3 && (b.size() < 3 || areaA > areaB)) ? a : b;
      ++removed;
      if (c.points.size() < 3 || c.points.size() >= n + 1)
      {
        break;
      }
    }
  }
  return removed;
}

/** Closed contours resampled at equal arc lengths of about \a spacing (at
 * least 8 points), from their first point; open contours unchanged. */
Contours
Resample(const Contours & contours, double spacing)
{
  Contours result = contours;
  for (auto & c : result)
  {
    const double length = Length(c);
    if (!c.closed || !(length > 0.0) || !(spacing > 0.0))
    {
      continue;
    }
    const auto          count = static_cast<size_t>(std::max(8.0, std::round(length / spacing)));
    const double        step = length / static_cast<double>(count);
    std::vector<Point2> points;
    points.reserve(count);
    size_t edge = 0;
    double edgeStart = 0.0; // arc length at the start of edge
    double edgeLength = c.points[0].EuclideanDistanceTo(c.points[1 % c.points.size()]);
    for (size_t i = 0; i < count; ++i)
    {
      const double s = static_cast<double>(i) * step;
      while (edge + 1 < c.points.size() && s > edgeStart + edgeLength)
      {
        edgeStart += edgeLength;
        ++edge;
        edgeLength = c.points[edge].EuclideanDistanceTo(c.points[(edge + 1) % c.points.size()]);
      }
      const double t = edgeLength > 0.0 ? std::min(1.0, (s - edgeStart) / edgeLength) : 0.0;
      const auto & a = c.points[edge];
      const auto & b = c.points[(edge + 1) % c.points.size()];
      points.push_back(MakePoint(a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1])));
    }
    c.points = points;
  }
  return result;
}

/** The contours as the filter's mesh: the points numbered contour after
 * contour, a closed contour as one polygon cell, an open one as a chain of
 * line cells. */
ContourMeshType::Pointer
ToMesh(const Contours & contours)
{
  using CellType = ContourMeshType::CellType;
  auto                mesh = ContourMeshType::New();
  auto                points = ContourMeshType::PointsContainer::New();
  itk::IdentifierType next = 0;
  itk::IdentifierType cellId = 0;
  points->Reserve(CountPoints(contours));
  for (const auto & c : contours)
  {
    const itk::IdentifierType first = next;
    for (const auto & p : c.points)
    {
      points->SetElement(next++, p);
    }
    if (c.closed)
    {
      CellType::CellAutoPointer cell;
      cell.TakeOwnership(new itk::PolygonCell<CellType>);
      for (itk::IdentifierType k = 0; k < c.points.size(); ++k)
      {
        cell->SetPointId(static_cast<int>(k), first + k);
      }
      mesh->SetCell(cellId++, cell);
    }
    else
    {
      for (itk::IdentifierType k = 0; k + 1 < c.points.size(); ++k)
      {
        CellType::CellAutoPointer cell;
        cell.TakeOwnership(new itk::LineCell<CellType>);
        cell->SetPointId(0, first + k);
        cell->SetPointId(1, first + k + 1);
        mesh->SetCell(cellId++, cell);
      }
    }
  }
  mesh->SetPoints(points);
  return mesh;
}

/** The filter's output back as contours of the layout of \a layout (the
 * filter keeps the input's numbering). */
Contours
FromMesh(const ContourMeshType * mesh, const Contours & layout)
{
  Contours            result = layout;
  itk::IdentifierType next = 0;
  for (auto & c : result)
  {
    for (auto & p : c.points)
    {
      p = mesh->GetPoint(next++);
    }
  }
  return result;
}

#ifdef EDM_HAVE_VTK
/** The contours as a 3-D mesh (z = 0) of line cells, for the .pvd series (a build
 * with VTK). */
MeshType::Pointer
ToSurfaceMesh(const Contours & contours)
{
  using CellType = MeshType::CellType;
  auto                mesh = MeshType::New();
  itk::IdentifierType next = 0;
  itk::IdentifierType cellId = 0;
  for (const auto & c : contours)
  {
    const itk::IdentifierType first = next;
    for (const auto & p : c.points)
    {
      MeshType::PointType q;
      q[0] = p[0];
      q[1] = p[1];
      q[2] = 0.0;
      mesh->SetPoint(next++, q);
    }
    for (size_t k = 0; k < CountEdges(c); ++k)
    {
      CellType::CellAutoPointer cell;
      cell.TakeOwnership(new itk::LineCell<CellType>);
      cell->SetPointId(0, first + k);
      cell->SetPointId(1, first + (k + 1) % c.points.size());
      mesh->SetCell(cellId++, cell);
    }
  }
  return mesh;
}
#endif

/** A contour with too few points, or points that are not finite, is bad
 * input. */
void
CheckContour(const Contour & c, const std::string & what)
{
  std::set<std::pair<double, double>> distinct;
  for (const auto & p : c.points)
  {
    if (!(std::abs(p[0]) <= 1e12 && std::abs(p[1]) <= 1e12))
    {
      throw Error(what + " has a point at " + Format(p[0], 6) + ", " + Format(p[1], 6) +
                  ": edmodel needs finite coordinates within 1e+12 of 0");
    }
    distinct.insert({ p[0], p[1] });
  }
  const size_t needed = c.closed ? 3 : 2;
  if (distinct.size() < needed)
  {
    throw Error(what + " has " + std::to_string(distinct.size()) + " distinct point" +
                (distinct.size() == 1 ? "" : "s") + ": a" + (c.closed ? " closed" : "n open") + " contour needs " +
                std::to_string(needed));
  }
}

// --- Reading contours -------------------------------------------------------

/** x,y points, one per line: a first line that is not numbers is a header,
 * '#' starts a comment, an empty line ends a contour; separators ',', ';',
 * spaces or tabs; a third number (z) is ignored. Closed contours unless
 * \a open; a closed contour whose last point repeats its first drops it. */
Contours
ReadCsvContours(const std::string & path, bool open)
{
  std::ifstream stream(path, std::ios::binary);
  if (!stream)
  {
    throw Error("--init-contour: cannot read contour " + Quote(path));
  }
  Contours    contours;
  Contour     current;
  std::string line;
  size_t      number = 0;
  bool        seenData = false;
  const auto  finish = [&]() {
    if (!current.points.empty())
    {
      current.closed = !open;
      if (current.closed && current.points.size() > 1 &&
          current.points.front().EuclideanDistanceTo(current.points.back()) == 0.0)
      {
        current.points.pop_back();
      }
      contours.push_back(current);
      current = Contour();
    }
  };
  while (std::getline(stream, line))
  {
    ++number;
    if (number > 100000000)
    {
      throw Error("--init-contour: " + Quote(path) + " has more than 1e8 lines");
    }
    const auto hash = line.find('#');
    if (hash != std::string::npos)
    {
      line.erase(hash);
    }
    for (auto & ch : line)
    {
      ch = (ch == ',' || ch == ';' || ch == '\t' || ch == '\r') ? ' ' : ch;
    }
    std::istringstream       fields(line);
    std::vector<std::string> items;
    std::string              item;
    while (fields >> item)
    {
      items.push_back(item);
    }
    if (items.empty())
    {
      if (line.find_first_not_of(' ') == std::string::npos && hash == std::string::npos)
      {
        finish();
      }
      continue;
    }
    std::vector<double> values;
    bool                numbers = items.size() == 2 || items.size() == 3;
    for (const auto & text : items)
    {
      char *       end = nullptr;
      const double value = std::strtod(text.c_str(), &end);
      numbers = numbers && end != text.c_str() && *end == '\0';
      values.push_back(value);
    }
    if (!numbers)
    {
      if (!seenData && contours.empty() && current.points.empty())
      {
        seenData = true; // the header
        continue;
      }
      throw Error("--init-contour: " + Quote(path) + " line " + std::to_string(number) +
                  ": expected x,y (two numbers), found '" + line + "'");
    }
    seenData = true;
    if (!(std::isfinite(values[0]) && std::isfinite(values[1])))
    {
      throw Error("--init-contour: " + Quote(path) + " line " + std::to_string(number) + ": non-finite coordinate");
    }
    current.points.push_back(MakePoint(values[0], values[1]));
  }
  finish();
  if (contours.empty())
  {
    throw Error("--init-contour: " + Quote(path) + " has no points");
  }
  return contours;
}

/** The curves of a mesh's line, polyline and polygon cells, followed from
 * point to point: a chain with two ends is open, a loop is closed. A point
 * with more than two neighbours (a branch) or a triangle is an error. */
Contours
ContoursFromMesh(const MeshType * mesh, const std::string & path)
{
  std::set<std::pair<itk::IdentifierType, itk::IdentifierType>> edges;
  const auto addEdge = [&edges](itk::IdentifierType a, itk::IdentifierType b) {
    if (a != b)
    {
      edges.insert({ std::min(a, b), std::max(a, b) });
    }
  };
  if (mesh->GetCells() != nullptr)
  {
    for (auto it = mesh->GetCells()->Begin(); it != mesh->GetCells()->End(); ++it)
    {
      const auto * cell = it.Value();
      const auto   type = cell->GetType();
      const auto * ids = cell->GetPointIds();
      const auto   n = cell->GetNumberOfPoints();
      if (type == itk::CellGeometryEnum::LINE_CELL)
      {
        for (unsigned int k = 0; k + 1 < n; ++k)
        {
          addEdge(ids[k], ids[k + 1]);
        }
      }
      else if (type == itk::CellGeometryEnum::POLYGON_CELL && n >= 3)
      {
        for (unsigned int k = 0; k < n; ++k)
        {
          addEdge(ids[k], ids[(k + 1) % n]);
        }
      }
      else if (type == itk::CellGeometryEnum::TRIANGLE_CELL || type == itk::CellGeometryEnum::QUADRILATERAL_CELL)
      {
        throw Error("--init-contour: " + Quote(path) +
                    " has triangles: a contour is made of polylines or polygons (a surface goes with --init-mesh on "
                    "a 3-D image)");
      }
    }
  }
  if (edges.empty())
  {
    throw Error("--init-contour: " + Quote(path) + " has no lines or polygons");
  }
  std::map<itk::IdentifierType, std::vector<itk::IdentifierType>> neighbours;
  for (const auto & e : edges)
  {
    neighbours[e.first].push_back(e.second);
    neighbours[e.second].push_back(e.first);
  }
  for (const auto & entry : neighbours)
  {
    if (entry.second.size() > 2)
    {
      throw Error("--init-contour: " + Quote(path) + ": point " + std::to_string(entry.first) + " joins " +
                  std::to_string(entry.second.size()) + " lines; contours must not branch");
    }
  }
  std::set<itk::IdentifierType> visited;
  Contours                      contours;
  const auto                    follow = [&](itk::IdentifierType start, bool closed) {
    Contour c;
    c.closed = closed;
    itk::IdentifierType previous = start;
    itk::IdentifierType current = start;
    while (true)
    {
      visited.insert(current);
      const auto & p = mesh->GetPoint(current);
      c.points.push_back(MakePoint(p[0], p[1]));
      bool moved = false;
      for (const auto next : neighbours[current])
      {
        if (next != previous && visited.count(next) == 0)
        {
          previous = current;
          current = next;
          moved = true;
          break;
        }
      }
      if (!moved)
      {
        break;
      }
    }
    contours.push_back(c);
  };
  for (const auto & entry : neighbours) // open chains, from an end
  {
    if (entry.second.size() == 1 && visited.count(entry.first) == 0)
    {
      follow(entry.first, false);
    }
  }
  for (const auto & entry : neighbours) // the rest are loops
  {
    if (visited.count(entry.first) == 0)
    {
      follow(entry.first, true);
    }
  }
  return contours;
}

Contours
ReadInitialContours(const SegmentOptions & o)
{
  Contours contours;
  if (GetExtension(o.initContour) == ".csv" || GetExtension(o.initContour) == ".txt")
  {
    std::error_code error;
    if (!fs::is_regular_file(o.initContour, error))
    {
      throw Error("--init-contour: cannot read contour " + Quote(o.initContour) + ": " +
                  (fs::exists(o.initContour, error) ? "not a regular file" : "no such file or directory"));
    }
    contours = ReadCsvContours(o.initContour, o.openContour);
  }
  else
  {
    if (o.openContour)
    {
      throw Error("--open applies to .csv contours: in " + Quote(o.initContour) +
                  " a polyline is closed when it ends on its first point");
    }
    const MeshType::Pointer mesh = ReadCurveMesh(o.initContour, "--init-contour");
    contours = ContoursFromMesh(mesh, o.initContour);
  }
  for (size_t k = 0; k < contours.size(); ++k)
  {
    CheckContour(contours[k],
                 "--init-contour: " + Quote(o.initContour) +
                   (contours.size() > 1 ? " contour " + std::to_string(k + 1) : std::string()));
  }
  return contours;
}

Contours
MakeInitialCircle(const Image2DType * image, const SegmentOptions & o)
{
  Point2 center;
  double radius = 0.0;
  if (o.hasInitCircle)
  {
    center = MakePoint(o.circle[0], o.circle[1]);
    radius = o.circle[2];
    if (!IsInsideImage(image, center))
    {
      throw Error("--init-circle: the centre (" + Format(o.circle[0], 6) + ", " + Format(o.circle[1], 6) +
                  ") is outside the image (" + DescribeBounds(image) + ")");
    }
  }
  else
  {
    const auto &                    region = image->GetLargestPossibleRegion();
    itk::ContinuousIndex<double, 2> middle;
    double                          smallestExtent = 1e300;
    for (unsigned int k = 0; k < 2; ++k)
    {
      middle[k] = region.GetIndex()[k] + 0.5 * (static_cast<double>(region.GetSize()[k]) - 1.0);
      smallestExtent = std::min(smallestExtent, region.GetSize()[k] * image->GetSpacing()[k]);
    }
    image->TransformContinuousIndexToPhysicalPoint(middle, center);
    radius = defaults::SphereRadiusOverExtent * smallestExtent;
  }
  Contour circle;
  circle.closed = true;
  for (unsigned int k = 0; k < o.circlePoints; ++k)
  {
    const double t = 2.0 * 3.141592653589793 * k / o.circlePoints;
    circle.points.push_back(MakePoint(center[0] + radius * std::cos(t), center[1] + radius * std::sin(t)));
    if (!IsInsideImage(image, circle.points.back()))
    {
      throw Error("--init-circle: the circle of centre (" + Format(center[0], 6) + ", " + Format(center[1], 6) +
                  ") and radius " + Format(radius, 6) + " mm extends outside the image (" + DescribeBounds(image) +
                  ")");
    }
  }
  return { circle };
}

void
CheckInitialContours(const Image2DType * image,
                     const Contours &    contours,
                     const std::string & path,
                     Progress &          progress)
{
  size_t outside = 0;
  for (const auto & c : contours)
  {
    for (const auto & p : c.points)
    {
      outside += IsInsideImage(image, p) ? 0 : 1;
    }
  }
  const size_t n = CountPoints(contours);
  if (outside == n)
  {
    throw Error("--init-contour: contour " + Quote(path) + " lies outside the image (" + DescribeBounds(image) + ")");
  }
  if (outside > 0)
  {
    progress.Note("warning: " + std::to_string(outside) + " of " + std::to_string(n) +
                  " points of the initial contour are outside the image and feel no external force");
  }
}

// --- Writing contours -------------------------------------------------------

bool
IsContourExtension(const std::string & extension)
{
  return extension == ".csv" || extension == ".vtk" || (extension == ".vtp" && HasVTK());
}

std::string
ContourExtensionsText()
{
  return HasVTK() ? ".csv, .vtk or .vtp" : ".csv or .vtk (.vtp needs a build with VTK)";
}

void
CheckOutputDirectoryOf(const std::string & path, const std::string & option)
{
  const fs::path  parent = fs::path(path).has_parent_path() ? fs::path(path).parent_path() : fs::path(".");
  std::error_code error;
  if (!fs::is_directory(parent, error))
  {
    throw Error(option + ": directory '" + parent.string() + "' does not exist");
  }
  if (fs::is_directory(path, error))
  {
    throw Error(option + ": " + Quote(path) + " is a directory");
  }
}

void
CheckContourOutputPath(const std::string & path, const std::string & option)
{
  const std::string extension = GetExtension(path);
  if (!IsContourExtension(extension))
  {
    throw Error(option + ": " +
                (extension == ".vtp" ? std::string("writing .vtp needs VTK, and this edmodel was built without VTK")
                                     : "unknown contour extension '" + extension + "' in " + Quote(path)) +
                " (a contour of a 2-D image is written as " + ContourExtensionsText() + ")");
  }
  CheckOutputDirectoryOf(path, option);
}

/** Coordinates printed so that a double reads back within 1e-12 relative. */
std::string
Coordinate(double value)
{
  std::ostringstream stream;
  stream << std::setprecision(12) << value;
  return stream.str();
}

/** x,y per line, a header, an empty line between contours. */
std::string
ContoursAsCsv(const Contours & contours)
{
  std::string text = "x,y\n";
  for (size_t c = 0; c < contours.size(); ++c)
  {
    text += c == 0 ? "" : "\n";
    for (const auto & p : contours[c].points)
    {
      text += Coordinate(p[0]) + "," + Coordinate(p[1]) + "\n";
    }
  }
  return text;
}

/** Legacy VTK POLYDATA: the points (z = 0) and one polyline per contour,
 * closed ones ending on their first point. */
std::string
ContoursAsLegacyVTK(const Contours & contours)
{
  std::string text = "# vtk DataFile Version 3.0\nedmodel contour\nASCII\nDATASET POLYDATA\nPOINTS " +
                     std::to_string(CountPoints(contours)) + " double\n";
  for (const auto & c : contours)
  {
    for (const auto & p : c.points)
    {
      text += Coordinate(p[0]) + " " + Coordinate(p[1]) + " 0\n";
    }
  }
  size_t size = 0;
  for (const auto & c : contours)
  {
    size += 1 + c.points.size() + (c.closed ? 1 : 0);
  }
  text += "LINES " + std::to_string(contours.size()) + " " + std::to_string(size) + "\n";
  size_t first = 0;
  for (const auto & c : contours)
  {
    text += std::to_string(c.points.size() + (c.closed ? 1 : 0));
    for (size_t k = 0; k < c.points.size(); ++k)
    {
      text += " " + std::to_string(first + k);
    }
    text += c.closed ? " " + std::to_string(first) : std::string();
    text += "\n";
    first += c.points.size();
  }
  return text;
}

#ifdef EDM_HAVE_VTK
std::string
ContoursAsVTP(const Contours & contours)
{
  vtkObject::GlobalWarningDisplayOff();
  vtkNew<vtkPoints> points;
  points->SetDataTypeToDouble();
  vtkNew<vtkCellArray> lines;
  vtkIdType            first = 0;
  for (const auto & c : contours)
  {
    std::vector<vtkIdType> ids;
    for (const auto & p : c.points)
    {
      points->InsertNextPoint(p[0], p[1], 0.0);
      ids.push_back(first + static_cast<vtkIdType>(ids.size()));
    }
    if (c.closed)
    {
      ids.push_back(first);
    }
    lines->InsertNextCell(static_cast<vtkIdType>(ids.size()), ids.data());
    first += static_cast<vtkIdType>(c.points.size());
  }
  vtkNew<vtkPolyData> polyData;
  polyData->SetPoints(points);
  polyData->SetLines(lines);
  vtkNew<vtkXMLPolyDataWriter> writer;
  writer->SetInputData(polyData);
  writer->WriteToOutputStringOn();
  writer->SetDataModeToBinary(); // inline: ParaView 5.11 on Debian 12 cannot parse appended data
  writer->SetCompressorTypeToZLib();
  if (writer->Write() != 1)
  {
    throw Error("cannot write the contour as .vtp");
  }
  return writer->GetOutputString();
}
#endif

void
WriteContours(const Contours & contours, const std::string & path)
{
  const std::string extension = GetExtension(path);
  std::string       text;
  if (extension == ".csv")
  {
    text = ContoursAsCsv(contours);
  }
  else if (extension == ".vtk")
  {
    text = ContoursAsLegacyVTK(contours);
  }
  else
  {
#ifdef EDM_HAVE_VTK
    text = ContoursAsVTP(contours);
#else
    throw Error("cannot write " + Quote(path) + ": this edmodel was built without VTK");
#endif
  }
  AtomicOutput output(path);
  WriteFileContents(text, output.GetTemporaryPath());
  output.Commit();
}

// --- The overlay PNG --------------------------------------------------------

using RGBPixelType = itk::RGBPixel<unsigned char>;
using RGBImageType = itk::Image<RGBPixelType, 2>;

/** The image in grey (its 0.5th to 99.5th percentile), each pixel drawn
 * with its physical aspect ratio, enlarged to at least 512 pixels across,
 * the initial contours in yellow and the final ones in red. */
void
WriteOverlay(const Image2DType * image, const Contours & initial, const Contours & final, const std::string & path)
{
  const auto   size = image->GetLargestPossibleRegion().GetSize();
  const auto   start = image->GetLargestPossibleRegion().GetIndex();
  const double smallest = SmallestSpacing(image);
  // Width and height in pixels of the smallest spacing, then enlarged.
  const double width = size[0] * image->GetSpacing()[0] / smallest;
  const double height = size[1] * image->GetSpacing()[1] / smallest;
  const double zoom =
    std::max(1.0, std::min(std::ceil(512.0 / std::max(width, height)), 4096.0 / std::max(width, height)));
  RGBImageType::SizeType outputSize;
  outputSize[0] = std::max<itk::SizeValueType>(1, static_cast<itk::SizeValueType>(std::lround(width * zoom)));
  outputSize[1] = std::max<itk::SizeValueType>(1, static_cast<itk::SizeValueType>(std::lround(height * zoom)));

  std::vector<float> values(image->GetBufferPointer(),
                            image->GetBufferPointer() + image->GetBufferedRegion().GetNumberOfPixels());
  const auto         percentile = [&values](double q) {
    const size_t k = static_cast<size_t>(q * static_cast<double>(values.size() - 1));
    std::nth_element(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(k), values.end());
    return static_cast<double>(values[k]);
  };
  double low = percentile(0.005);
  double high = percentile(0.995);
  if (!(high > low))
  {
    low = *std::min_element(values.begin(), values.end());
    high = *std::max_element(values.begin(), values.end());
  }
  const double range = high > low ? high - low : 1.0;

  auto overlay = RGBImageType::New();
  overlay->SetRegions(outputSize);
  overlay->Allocate();
  const double scaleX = static_cast<double>(outputSize[0]) / size[0];
  const double scaleY = static_cast<double>(outputSize[1]) / size[1];
  for (itk::SizeValueType v = 0; v < outputSize[1]; ++v)
  {
    for (itk::SizeValueType u = 0; u < outputSize[0]; ++u)
    {
      Image2DType::IndexType index;
      index[0] =
        start[0] + std::min<itk::IndexValueType>(size[0] - 1, static_cast<itk::IndexValueType>((u + 0.5) / scaleX));
      index[1] =
        start[1] + std::min<itk::IndexValueType>(size[1] - 1, static_cast<itk::IndexValueType>((v + 0.5) / scaleY));
      const double t = std::min(1.0, std::max(0.0, (image->GetPixel(index) - low) / range));
      const auto   grey = static_cast<unsigned char>(std::lround(255.0 * t));
      RGBPixelType pixel;
      pixel.Set(grey, grey, grey);
      RGBImageType::IndexType out = { { static_cast<itk::IndexValueType>(u), static_cast<itk::IndexValueType>(v) } };
      overlay->SetPixel(out, pixel);
    }
  }

  const auto draw = [&](const Contours & contours, RGBPixelType colour, double radius) {
    const auto toOutput = [&](const Point2 & p, double & u, double & v) {
      itk::ContinuousIndex<double, 2> index;
      static_cast<void>(image->TransformPhysicalPointToContinuousIndex(p, index));
      u = (index[0] - start[0] + 0.5) * scaleX - 0.5;
      v = (index[1] - start[1] + 0.5) * scaleY - 0.5;
    };
    for (const auto & c : contours)
    {
      for (size_t k = 0; k < CountEdges(c); ++k)
      {
        double u0 = 0.0;
        double v0 = 0.0;
        double u1 = 0.0;
        double v1 = 0.0;
        toOutput(c.points[k], u0, v0);
        toOutput(c.points[(k + 1) % c.points.size()], u1, v1);
        const double length = std::hypot(u1 - u0, v1 - v0);
        if (!(length < 1e6))
        {
          continue;
        }
        const int steps = static_cast<int>(std::ceil(2.0 * length)) + 1;
        for (int s = 0; s <= steps; ++s)
        {
          const double u = u0 + (u1 - u0) * s / steps;
          const double v = v0 + (v1 - v0) * s / steps;
          for (long y = std::lround(v - radius); y <= std::lround(v + radius); ++y)
          {
            for (long x = std::lround(u - radius); x <= std::lround(u + radius); ++x)
            {
              if (x >= 0 && y >= 0 && x < static_cast<long>(outputSize[0]) && y < static_cast<long>(outputSize[1]) &&
                  (x - u) * (x - u) + (y - v) * (y - v) <= radius * radius)
              {
                RGBImageType::IndexType out = { { x, y } };
                overlay->SetPixel(out, colour);
              }
            }
          }
        }
      }
    }
  };
  const double lineRadius = std::max(1.0, std::min(outputSize[0], outputSize[1]) / 400.0);
  RGBPixelType yellow;
  yellow.Set(255, 220, 0);
  RGBPixelType red;
  red.Set(255, 0, 0);
  draw(initial, yellow, 0.7 * lineRadius);
  draw(final, red, lineRadius);

  AtomicOutput output(path);
  auto         writer = itk::ImageFileWriter<RGBImageType>::New();
  writer->SetInput(overlay);
  writer->SetFileName(output.GetTemporaryPath());
  try
  {
    writer->Update();
  }
  catch (const itk::ExceptionObject & exception)
  {
    throw Error("cannot write " + Quote(path) + ": " + OneLine(exception.GetDescription()));
  }
  output.Commit();
}

// --- The deformation --------------------------------------------------------

struct ContourResult
{
  Contours             contours;
  Force2DType::Pointer force;
  itk::SizeValueType   iterations{ 0 };
  bool                 converged{ false };
  double               lastMaximumDisplacement{ 0.0 };
};

using ContourSnapshot = std::function<void(const Contours &, itk::SizeValueType)>;

bool
HasOpenContour(const Contours & contours)
{
  return std::any_of(contours.begin(), contours.end(), [](const Contour & c) { return !c.closed; });
}

/** The force field and the deformation, by the ITK filters, with the
 * schedule of the 3-D surfaces (edmodelPipeline.cxx): defaults from the
 * smallest pixel spacing, the region force's intensity model estimated
 * inside the initial contour, and coarse to fine (each edge split in two
 * between levels) until the mean edge is about --edge-length. */
ContourResult
DeformContours(const Image2DType *     image,
               const Contours &        initial,
               const SegmentOptions &  o,
               Progress &              progress,
               const ContourSnapshot & snapshot)
{
  ContourResult result;
  const double  smallest = SmallestSpacing(image);
  const double  scale = ForceScale(image, o);

  // Outward is undefined on an open contour: no region force there.
  const bool    open = HasOpenContour(initial);
  LevelSchedule schedule;
  schedule.scale = scale;
  schedule.regionWeight = open                    ? 0.0
                          : o.regionWeight >= 0.0 ? o.regionWeight
                                                  : defaults::RegionWeightInVoxels * smallest;
  schedule.regionSigma = o.regionSigma >= 0.0 ? o.regionSigma : defaults::RegionSigmaInVoxels * smallest;
  schedule.edgeSearchWeight = open                        ? 0.0
                              : o.edgeSearchWeight >= 0.0 ? o.edgeSearchWeight
                                                          : defaults::EdgeSearchWeightInVoxels * smallest;
  schedule.edgeSearchDistance =
    o.edgeSearchDistance > 0.0 ? o.edgeSearchDistance : defaults::EdgeSearchDistanceInVoxels * smallest;
  schedule.edgeLength = o.edgeLength > 0.0 ? o.edgeLength : defaults::EdgeLengthInVoxels * smallest;
  schedule.tangentialElasticity =
    o.tangentialElasticityGiven ? o.tangentialElasticity : defaults::ContourTangentialElasticity;
  // The tangential elasticity keeps spacing the points evenly along the
  // contour after its shape has settled (the capture level's last third of
  // iterations on an ellipse: 0.02 to 0.03 mm along the contour, 0.002 mm
  // across it); convergence looks at the motion across the contour.
  schedule.convergenceAlongNormals = true;
  schedule.captureRegionWeightFactor = defaults::ContourCaptureRegionWeightFactor;
  schedule.captureRegionSigmaFactor = defaults::ContourCaptureRegionSigmaFactor;
  schedule.pointsWord = "points";
  schedule.initialWhat = "contour";
  if (open && o.regionWeight < 0.0)
  {
    progress.Note("open contour: no region force (outward is undefined); gradient forces only");
  }

  // With the defaults the force field and the region force smooth the image
  // by the same Gaussian (one pixel, at every level): it is smoothed once
  // here, by the function both filters use (SmoothWithSampledGaussian), and
  // neither filter smooths it again (the same values; on a 128 x 128 image
  // the second smoothing was a tenth of the computation). A sigma beyond the
  // image's extent is left to the force filter, whose error names it.
  const double forceSigma = ForceSigma(image, o);
  const auto   imageSize = image->GetLargestPossibleRegion().GetSize();
  double       largestExtent = 0.0;
  for (unsigned int d = 0; d < 2; ++d)
  {
    largestExtent = std::max(largestExtent, static_cast<double>(imageSize[d]) * image->GetSpacing()[d]);
  }
  const bool shareSmoothing = schedule.regionWeight > 0.0 && forceSigma > 0.0 && forceSigma <= largestExtent &&
                              schedule.regionSigma == forceSigma && schedule.captureRegionSigmaFactor == 1.0;
  Image2DType::ConstPointer intensity = image;
  if (shareSmoothing)
  {
    Image2DType::Pointer smoothed = Image2DType::New();
    Image2DType::Pointer scratch = Image2DType::New();
    for (Image2DType * buffer : { smoothed.GetPointer(), scratch.GetPointer() })
    {
      buffer->CopyInformation(image);
      buffer->SetRegions(image->GetBufferedRegion());
      buffer->Allocate();
    }
    std::copy(image->GetBufferPointer(),
              image->GetBufferPointer() + image->GetBufferedRegion().GetNumberOfPixels(),
              smoothed->GetBufferPointer());
    itk::SmoothWithSampledGaussian<Image2DType>(smoothed, scratch, forceSigma, itk::MultiThreaderBase::New());
    intensity = smoothed;
    schedule.regionSigma = 0.0;
  }
  result.force = ComputeForceField<Force2DFilterType>(intensity, o, progress, shareSmoothing);

  // A contour inside the image is at most a few times the image's
  // perimeter long: refining beyond 4 times that many edges of
  // --edge-length means it has left the image or tangled (checked after the
  // run); the levels stop there.
  const double perimeter = 2.0 * (imageSize[0] * image->GetSpacing()[0] + imageSize[1] * image->GetSpacing()[1]);
  const double maximumPoints = std::min<double>(defaults::MaximumRefinedPoints, 4.0 * perimeter / schedule.edgeLength);
  Contours     stageInput = initial;
  LevelState   state;
  if (snapshot)
  {
    snapshot(initial, 0);
  }
  // One filter for all levels: its smoothed intensity image and statistics
  // are kept from one level to the next when the region sigma is the same.
  auto deform = ContourFilterType::New();
  // Closed contours pushed outward (region force or balloon) are watched
  // every ContourCheckInterval iterations: a contour that grew around an
  // obstacle (on a brain slice, the ventricles the initial circle sits
  // between) closes behind it by crossing itself, and its points, left with
  // edges of tens of pixels, tangle further (it ended wound four times around
  // the brain). At a crossing the level stops, the contour loses its loops
  // (RemoveLoops) and is resampled, and the level starts again from it; so
  // does the capture level when its longest edge exceeds
  // ContourCaptureStretch times the initial mean edge.
  const bool         watch = !open && (schedule.regionWeight > 0.0 || o.balloon != 0.0);
  const double       initialMeanEdge = MeanEdgeLength(initial);
  unsigned int       restarts = 0;
  itk::SizeValueType stageIterationsBefore = 0; // of the current stage, before its restarts
  for (unsigned int stage = 0;;)
  {
    // Unlike the 3-D sphere, the initial circle is often already as fine as
    // --edge-length (a small circle inside the object): the first level is
    // then a capture level anyway, and a last level at the same resolution
    // follows it.
    const bool last = schedule.regionWeight == 0.0;
    deform->SetInput(ToMesh(stageInput));
    deform->SetForceImage(result.force);
    deform->SetIntensityImage(intensity);
    const double stageMeanEdge = MeanEdgeLength(stageInput);
    ConfigureLevel(deform.GetPointer(), o, schedule, state, stage, last, stageMeanEdge);
    const auto cap = deform->GetNumberOfIterations();
    deform->SetNumberOfIterations(cap > stageIterationsBefore ? cap - stageIterationsBefore : 1);
    const bool capture = stage == 0 && !last;
    Contours   repaired;
    const auto checkpoint = [&]() {
      Contours current = FromMesh(deform->GetOutput(), stageInput);
      size_t   k = 0;
      size_t   m = 0;
      Point2   where;
      bool     crossing = false;
      for (const auto & c : current)
      {
        crossing = crossing || FindCrossing(c, k, m, where);
      }
      const bool stretched = capture && LongestEdge(current) > defaults::ContourCaptureStretch * initialMeanEdge;
      if (!crossing && !stretched)
      {
        return false;
      }
      const size_t loops = RemoveLoops(current);
      // The capture keeps at most twice the initial spacing; a refined
      // level its own.
      const double spacing = capture ? std::min(MeanEdgeLength(current), 2.0 * initialMeanEdge) : stageMeanEdge;
      repaired = Resample(current, spacing);
      progress.Note(
        "contour " +
        std::string(loops > 0 ? "crossed itself: " + std::to_string(loops) + " loop(s) removed, " : "stretched: ") +
        "resampled to " + std::to_string(CountPoints(repaired)) + " points");
      return true;
    };
    const bool checked = watch && restarts < defaults::ContourMaximumRestarts;
    const bool restart = RunLevel(deform.GetPointer(),
                                  o,
                                  schedule,
                                  progress,
                                  CountPoints(stageInput),
                                  state,
                                  snapshot ? std::function<void(itk::SizeValueType)>([&](itk::SizeValueType iteration) {
                                    snapshot(FromMesh(deform->GetOutput(), stageInput), iteration);
                                  })
                                           : std::function<void(itk::SizeValueType)>(),
                                  checked ? defaults::ContourCheckInterval : 0,
                                  std::function<bool()>(checkpoint));
    result.iterations = state.iterations;
    result.converged = state.converged;
    result.lastMaximumDisplacement = state.lastMaximumDisplacement;
    if (restart)
    {
      ++restarts;
      stageIterationsBefore += deform->GetCurrentIteration();
      stageInput = repaired;
      continue;
    }
    stageIterationsBefore = 0;
    const unsigned int ran = stage++;
    Contours           output = FromMesh(deform->GetOutput(), stageInput);
    if (watch && !checked)
    {
      // No loop is left in the result, whatever the restarts' count (a
      // checked level's last checkpoint saw its output).
      RemoveLoops(output);
    }
    const bool fine = !(MeanEdgeLength(output) > 1.5 * schedule.edgeLength) ||
                      2.0 * static_cast<double>(CountPoints(output)) > maximumPoints;
    if (last || (ran > 0 && fine))
    {
      result.contours = output;
      break;
    }
    if (fine)
    {
      stageInput = output;
      continue;
    }
    // After the capture, the contour is refined in one go to about
    // --edge-length: it lies on the boundary already, and the midpoints of
    // its edges lie within L^2 / 8R of the curve (R its radius of curvature;
    // 0.05 pixel on the ellipse of bench/compare-skimage.py), so that
    // intermediate levels only repeat the set-up and the convergence window.
    stageInput = Subdivide(output);
    while (MeanEdgeLength(stageInput) > 1.5 * schedule.edgeLength &&
           2.0 * static_cast<double>(CountPoints(stageInput)) <= maximumPoints)
    {
      stageInput = Subdivide(stageInput);
    }
  }
  return result;
}

/** A contour that left the image or collapsed is a failed run (exit 1):
 * nothing is written. Points within one pixel beyond the image's edge are an
 * object cut by it, not a contour that left. */
void
CheckFinalContours(const Image2DType * image, const Contours & initial, const Contours & final)
{
  size_t outside = 0;
  for (const auto & c : final)
  {
    for (const auto & p : c.points)
    {
      outside += IsInsideImage(image, p, 1.0) ? 0 : 1;
    }
  }
  if (outside > 0)
  {
    throw Error("the contour left the image: " + std::to_string(outside) + " of " + std::to_string(CountPoints(final)) +
                  " points lie more than a pixel outside it (a balloon or region force too strong for the image's "
                  "edges?); nothing written",
                ExitFailure);
  }
  for (size_t k = 0; k < final.size(); ++k)
  {
    const bool   closed = final[k].closed;
    const double before = closed ? Area(initial[k]) : Length(initial[k]);
    const double after = closed ? Area(final[k]) : Length(final[k]);
    if (before > 0.0 && !(after >= 1e-3 * before))
    {
      throw Error("the contour collapsed: it " +
                    (closed ? "encloses " + Format(after) + " mm^2" : "is " + Format(after) + " mm long") + ", " +
                    Format(100.0 * after / before) + " % of the initial " + Format(before) +
                    (closed ? " mm^2" : " mm") + "; nothing written",
                  ExitFailure);
    }
  }
}

std::string
DescribeContours(const Contours & contours)
{
  size_t closed = 0;
  for (const auto & c : contours)
  {
    closed += c.closed ? 1 : 0;
  }
  std::string text = std::to_string(CountPoints(contours)) + " points, ";
  if (contours.size() == 1)
  {
    text += closed == 1 ? "closed" : "open";
  }
  else
  {
    text += std::to_string(contours.size()) + " contours (" + std::to_string(closed) + " closed)";
  }
  return text;
}

} // namespace

int
RunSegmentContour(const SegmentOptions & o, const GlobalOptions & global)
{
  // Every output is checked before the computation starts.
  CheckContourOutputPath(o.output, "--output");
  if (!o.forceOutput.empty())
  {
    CheckImageOutputPath(o.forceOutput, "--force-output");
    const std::string extension = GetExtension(o.forceOutput);
    if (extension == ".nii" || extension == ".nii.gz")
    {
      throw Error("--force-output: ITK's NIfTI writer cannot hold the force field of a 2-D image (2 components "
                  "per pixel): use .mha, .mhd, .nrrd or .nhdr");
    }
  }
  if (!o.overlayPng.empty())
  {
    if (GetExtension(o.overlayPng) != ".png")
    {
      throw Error("--overlay-png: " + Quote(o.overlayPng) + " must end in .png");
    }
    CheckOutputDirectoryOf(o.overlayPng, "--overlay-png");
  }
  if (o.preventSelfIntersections && o.preventSelfIntersectionsGiven)
  {
    throw Error("--prevent-self-intersections works on the triangles of surfaces, not on 2-D contours");
  }
  if (!o.snapshots.empty())
  {
    if (!HasVTK())
    {
      throw Error("--snapshots: the .pvd time series needs VTK, and this edmodel was built without VTK");
    }
    std::error_code error;
    if (fs::exists(o.snapshots, error) && !fs::is_directory(o.snapshots, error))
    {
      throw Error("--snapshots: '" + o.snapshots + "' is not a directory");
    }
    const fs::path directory(o.snapshots);
    const fs::path parent = directory.has_parent_path() ? directory.parent_path() : fs::path(".");
    if (!fs::is_directory(parent, error))
    {
      throw Error("--snapshots: directory '" + parent.string() + "' does not exist");
    }
  }

  Progress                   progress(global.quiet);
  const Image2DType::Pointer image = ReadImage2D(o.image, o.gradientVectorFlow);
  Contours                   initial;
  if (!o.initContour.empty())
  {
    initial = ReadInitialContours(o);
    CheckInitialContours(image, initial, o.initContour, progress);
  }
  else
  {
    initial = MakeInitialCircle(image, o);
  }
  if (HasOpenContour(initial))
  {
    if (o.regionWeight > 0.0)
    {
      throw Error("--region: the region force needs closed contours (outward is undefined on an open contour)");
    }
    if (o.balloon != 0.0)
    {
      throw Error("--balloon: the balloon needs closed contours (outward is undefined on an open contour)");
    }
    if (o.edgeSearchWeight > 0.0)
    {
      throw Error("--edge-search: the edge search needs closed contours (outward is undefined on an open contour)");
    }
  }
  const auto size = image->GetLargestPossibleRegion().GetSize();
  progress.Note("2-D image " + std::to_string(size[0]) + " x " + std::to_string(size[1]) + ", spacing " +
                Format(image->GetSpacing()[0]) + " x " + Format(image->GetSpacing()[1]) + " mm; initial contour " +
                DescribeContours(initial));

  std::unique_ptr<SnapshotSeries> series;
  ContourSnapshot                 snapshot;
#ifdef EDM_HAVE_VTK
  if (!o.snapshots.empty())
  {
    series = std::make_unique<SnapshotSeries>(o.snapshots, fs::path(o.output).stem().string());
    snapshot = [&series](const Contours & contours, itk::SizeValueType iteration) {
      series->Add(ToSurfaceMesh(contours), iteration);
    };
  }
#endif

  const ContourResult result = RunRepeated(o, progress, [&](Progress & runProgress, bool first) {
    return DeformContours(image, initial, o, runProgress, first ? snapshot : ContourSnapshot());
  });
  // Levels refine the contours: compare with the initial ones contour by
  // contour (the same layout).
  CheckFinalContours(image, initial, result.contours);

  if (!o.forceOutput.empty())
  {
    WriteImage(result.force.GetPointer(), o.forceOutput);
  }
  if (!o.overlayPng.empty())
  {
    WriteOverlay(image, initial, result.contours, o.overlayPng);
  }
  WriteContours(result.contours, o.output);
  if (series)
  {
    series->Commit();
    progress.Note("wrote " + std::to_string(series->GetNumberOfFiles()) + " snapshots, every " +
                  std::to_string(o.snapshotEvery) + " iterations: " + series->GetCollectionPath());
  }
  if (!global.quiet)
  {
    std::cout << "edmodel: wrote " << o.output << " (" << DescribeContours(result.contours) << ") after "
              << result.iterations << " iterations" << (result.converged ? ", converged" : ", not converged")
              << (o.overlayPng.empty() ? std::string() : "; overlay " + o.overlayPng) << std::endl;
  }
  return ExitSuccess;
}

} // namespace edm
