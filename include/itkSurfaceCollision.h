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
#ifndef itkSurfaceCollision_h
#define itkSurfaceCollision_h

#include "itkCommonEnums.h"
#include "itkIntTypes.h"
#include "itkMultiThreaderBase.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <limits>
#include <utility>
#include <vector>

namespace itk
{
/** Geometry of triangle pairs on flat double arrays (points given as
 * pointers to 3 doubles): the exact-enough predicates and distances the
 * collision test of SurfaceCollision is made of. */
namespace SurfaceCollisionDetail
{
inline double
Dot(const double * a, const double * b)
{
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

inline void
Subtract(const double * a, const double * b, double * r)
{
  r[0] = a[0] - b[0];
  r[1] = a[1] - b[1];
  r[2] = a[2] - b[2];
}

inline void
Cross(const double * a, const double * b, double * r)
{
  r[0] = a[1] * b[2] - a[2] * b[1];
  r[1] = a[2] * b[0] - a[0] * b[2];
  r[2] = a[0] * b[1] - a[1] * b[0];
}

/** Signed volume (times 6) of the tetrahedron (a, b, c, d): positive when d
 * lies on the side of the plane (a, b, c) its normal (b - a) x (c - a)
 * points to. Plain double arithmetic. */
inline double
Orient3D(const double * a, const double * b, const double * c, const double * d)
{
  double ab[3], ac[3], ad[3], n[3];
  Subtract(b, a, ab);
  Subtract(c, a, ac);
  Subtract(d, a, ad);
  Cross(ab, ac, n);
  return Dot(n, ad);
}

/** Squared distance between the segments [p0, p1] and [q0, q1] (closest
 * points by clamped parameters; parallel segments handled). */
inline double
SegmentSegmentDistanceSquared(const double * p0, const double * p1, const double * q0, const double * q1)
{
  double d1[3], d2[3], r[3];
  Subtract(p1, p0, d1);
  Subtract(q1, q0, d2);
  Subtract(p0, q0, r);
  const double a = Dot(d1, d1);
  const double e = Dot(d2, d2);
  const double f = Dot(d2, r);
  double       s = 0.0;
  double       t = 0.0;
  const auto   clamp01 = [](double v) { return v < 0.0 ? 0.0 : (v > 1.0 ? 1.0 : v); };
  if (a <= 0.0 && e <= 0.0)
  {
    return Dot(r, r);
  }
  if (a <= 0.0)
  {
    t = clamp01(f / e);
  }
  else
  {
    const double c = Dot(d1, r);
    if (e <= 0.0)
    {
      s = clamp01(-c / a);
    }
    else
    {
      const double b = Dot(d1, d2);
      const double denominator = a * e - b * b;
      s = denominator > 0.0 ? clamp01((b * f - c * e) / denominator) : 0.0;
      t = (b * s + f) / e;
      if (t < 0.0)
      {
        t = 0.0;
        s = clamp01(-c / a);
      }
      else if (t > 1.0)
      {
        t = 1.0;
        s = clamp01((b - c) / a);
      }
    }
  }
  double w[3];
  for (unsigned int k = 0; k < 3; ++k)
  {
    w[k] = (p0[k] + s * d1[k]) - (q0[k] + t * d2[k]);
  }
  return Dot(w, w);
}

/** Squared distance from point p to the triangle (a, b, c), by the Voronoi
 * regions of its vertices, edges and face; in the face region the distance
 * to the plane, so that a point above an axis-aligned triangle gets its
 * height exactly. */
inline double
PointTriangleDistanceSquared(const double * p, const double * a, const double * b, const double * c)
{
  double ab[3], ac[3], ap[3], bp[3], cp[3], w[3];
  Subtract(b, a, ab);
  Subtract(c, a, ac);
  Subtract(p, a, ap);
  const double d1 = Dot(ab, ap);
  const double d2 = Dot(ac, ap);
  if (d1 <= 0.0 && d2 <= 0.0)
  {
    return Dot(ap, ap);
  }
  Subtract(p, b, bp);
  const double d3 = Dot(ab, bp);
  const double d4 = Dot(ac, bp);
  if (d3 >= 0.0 && d4 <= d3)
  {
    return Dot(bp, bp);
  }
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0)
  {
    const double v = d1 / (d1 - d3);
    for (unsigned int k = 0; k < 3; ++k)
    {
      w[k] = ap[k] - v * ab[k];
    }
    return Dot(w, w);
  }
  Subtract(p, c, cp);
  const double d5 = Dot(ab, cp);
  const double d6 = Dot(ac, cp);
  if (d6 >= 0.0 && d5 <= d6)
  {
    return Dot(cp, cp);
  }
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0)
  {
    const double v = d2 / (d2 - d6);
    for (unsigned int k = 0; k < 3; ++k)
    {
      w[k] = ap[k] - v * ac[k];
    }
    return Dot(w, w);
  }
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0)
  {
    const double v = (d4 - d3) / ((d4 - d3) + (d5 - d6));
    for (unsigned int k = 0; k < 3; ++k)
    {
      w[k] = bp[k] - v * (c[k] - b[k]);
    }
    return Dot(w, w);
  }
  double n[3];
  Cross(ab, ac, n);
  const double nn = Dot(n, n);
  if (!(nn > 0.0))
  {
    return Dot(ap, ap); // degenerate triangle: handled by its edges
  }
  const double h = Dot(n, ap);
  return h * h / nn;
}

/** 2-D orientation of (a, b, c) in the coordinates (u, v) of the points. */
inline double
Orient2D(const double * a, const double * b, const double * c, unsigned int u, unsigned int v)
{
  return (b[u] - a[u]) * (c[v] - a[v]) - (b[v] - a[v]) * (c[u] - a[u]);
}

/** Closed 2-D segments [p0, p1] and [q0, q1] (coordinates u, v) meet. */
inline bool
Segments2DIntersect(const double * p0,
                    const double * p1,
                    const double * q0,
                    const double * q1,
                    unsigned int   u,
                    unsigned int   v)
{
  const double o1 = Orient2D(p0, p1, q0, u, v);
  const double o2 = Orient2D(p0, p1, q1, u, v);
  const double o3 = Orient2D(q0, q1, p0, u, v);
  const double o4 = Orient2D(q0, q1, p1, u, v);
  if (((o1 > 0.0 && o2 < 0.0) || (o1 < 0.0 && o2 > 0.0)) && ((o3 > 0.0 && o4 < 0.0) || (o3 < 0.0 && o4 > 0.0)))
  {
    return true;
  }
  // Collinear or touching: a point of one segment lies on the other.
  const auto onSegment = [u, v](const double * a, const double * b, const double * p) {
    return std::min(a[u], b[u]) <= p[u] && p[u] <= std::max(a[u], b[u]) && std::min(a[v], b[v]) <= p[v] &&
           p[v] <= std::max(a[v], b[v]);
  };
  return (o1 == 0.0 && onSegment(p0, p1, q0)) || (o2 == 0.0 && onSegment(p0, p1, q1)) ||
         (o3 == 0.0 && onSegment(q0, q1, p0)) || (o4 == 0.0 && onSegment(q0, q1, p1));
}

/** 2-D point p in the closed triangle (a, b, c). */
inline bool
PointInTriangle2D(const double * p,
                  const double * a,
                  const double * b,
                  const double * c,
                  unsigned int   u,
                  unsigned int   v)
{
  const double o1 = Orient2D(a, b, p, u, v);
  const double o2 = Orient2D(b, c, p, u, v);
  const double o3 = Orient2D(c, a, p, u, v);
  return (o1 >= 0.0 && o2 >= 0.0 && o3 >= 0.0) || (o1 <= 0.0 && o2 <= 0.0 && o3 <= 0.0);
}

/** The axes (u, v) of the coordinate plane onto which a plane of normal n
 * projects best (the largest component of n dropped). */
inline void
ProjectionAxes(const double * n, unsigned int & u, unsigned int & v)
{
  const double x = std::abs(n[0]);
  const double y = std::abs(n[1]);
  const double z = std::abs(n[2]);
  if (x >= y && x >= z)
  {
    u = 1;
    v = 2;
  }
  else if (y >= z)
  {
    u = 2;
    v = 0;
  }
  else
  {
    u = 0;
    v = 1;
  }
}

/** The closed segment [p, q], lying in the plane of the triangle t, meets t
 * (2-D test in the plane's best projection). */
inline bool
CoplanarSegmentTriangle(const double * p, const double * q, const double * const * t, const double * normal)
{
  unsigned int u = 0;
  unsigned int v = 1;
  ProjectionAxes(normal, u, v);
  if (PointInTriangle2D(p, t[0], t[1], t[2], u, v) || PointInTriangle2D(q, t[0], t[1], t[2], u, v))
  {
    return true;
  }
  for (unsigned int k = 0; k < 3; ++k)
  {
    if (Segments2DIntersect(p, q, t[k], t[(k + 1) % 3], u, v))
    {
      return true;
    }
  }
  return false;
}

/** The edges of triangle a that meet the closed triangle b, given the
 * orientations sa[k] of a's vertices with respect to b's plane. */
inline bool
EdgesOfAMeetB(const double * const * a, const double * const * b, const double * sa, const double * normalB)
{
  for (unsigned int k = 0; k < 3; ++k)
  {
    const unsigned int l = (k + 1) % 3;
    const double       s = sa[k];
    const double       t = sa[l];
    if ((s > 0.0 && t > 0.0) || (s < 0.0 && t < 0.0))
    {
      continue;
    }
    if (s == 0.0 && t == 0.0)
    {
      if (CoplanarSegmentTriangle(a[k], a[l], b, normalB))
      {
        return true;
      }
      continue;
    }
    // The segment reaches b's plane: its line meets the closed triangle when
    // the three orientations of the line with b's edges agree.
    const double o1 = Orient3D(a[k], a[l], b[0], b[1]);
    const double o2 = Orient3D(a[k], a[l], b[1], b[2]);
    const double o3 = Orient3D(a[k], a[l], b[2], b[0]);
    if ((o1 >= 0.0 && o2 >= 0.0 && o3 >= 0.0) || (o1 <= 0.0 && o2 <= 0.0 && o3 <= 0.0))
    {
      return true;
    }
  }
  return false;
}

/** Whether the closed triangles a and b (arrays of 3 points) share a point:
 * crossing, touching or coplanar overlap. Signs of plain double determinants:
 * exact for well-separated or clearly crossing triangles, uncertain only
 * within rounding of a contact. */
inline bool
TrianglesIntersect(const double * const * a, const double * const * b)
{
  double sb[3];
  double sa[3];
  for (unsigned int k = 0; k < 3; ++k)
  {
    sb[k] = Orient3D(a[0], a[1], a[2], b[k]);
  }
  if ((sb[0] > 0.0 && sb[1] > 0.0 && sb[2] > 0.0) || (sb[0] < 0.0 && sb[1] < 0.0 && sb[2] < 0.0))
  {
    return false;
  }
  for (unsigned int k = 0; k < 3; ++k)
  {
    sa[k] = Orient3D(b[0], b[1], b[2], a[k]);
  }
  if ((sa[0] > 0.0 && sa[1] > 0.0 && sa[2] > 0.0) || (sa[0] < 0.0 && sa[1] < 0.0 && sa[2] < 0.0))
  {
    return false;
  }
  double e1[3], e2[3], na[3], nb[3];
  Subtract(a[1], a[0], e1);
  Subtract(a[2], a[0], e2);
  Cross(e1, e2, na);
  Subtract(b[1], b[0], e1);
  Subtract(b[2], b[0], e2);
  Cross(e1, e2, nb);
  if (sb[0] == 0.0 && sb[1] == 0.0 && sb[2] == 0.0)
  {
    // Coplanar: an edge of one meets the other, or one contains the other.
    unsigned int u = 0;
    unsigned int v = 1;
    ProjectionAxes(na, u, v);
    for (unsigned int k = 0; k < 3; ++k)
    {
      for (unsigned int l = 0; l < 3; ++l)
      {
        if (Segments2DIntersect(a[k], a[(k + 1) % 3], b[l], b[(l + 1) % 3], u, v))
        {
          return true;
        }
      }
    }
    return PointInTriangle2D(a[0], b[0], b[1], b[2], u, v) || PointInTriangle2D(b[0], a[0], a[1], a[2], u, v);
  }
  // The intersection of two non-coplanar triangles, when not empty, is a
  // segment whose ends lie on edges of one or the other.
  return EdgesOfAMeetB(a, b, sa, nb) || EdgesOfAMeetB(b, a, sb, na);
}

/** Euclidean distance between the closed triangles a and b: 0 when they
 * intersect, otherwise the smallest of the 9 edge-edge and 6 vertex-face
 * distances (one of the closest points of two disjoint triangles lies on an
 * edge). */
inline double
TriangleDistance(const double * const * a, const double * const * b)
{
  if (TrianglesIntersect(a, b))
  {
    return 0.0;
  }
  double d2 = std::numeric_limits<double>::infinity();
  for (unsigned int k = 0; k < 3; ++k)
  {
    for (unsigned int l = 0; l < 3; ++l)
    {
      d2 = std::min(d2, SegmentSegmentDistanceSquared(a[k], a[(k + 1) % 3], b[l], b[(l + 1) % 3]));
    }
    d2 = std::min(d2, PointTriangleDistanceSquared(a[k], b[0], b[1], b[2]));
    d2 = std::min(d2, PointTriangleDistanceSquared(b[k], a[0], a[1], a[2]));
  }
  return std::sqrt(d2);
}

/** Triangles t and u (3 vertex indices each) share a vertex. */
inline bool
ShareVertex(const uint32_t * t, const uint32_t * u)
{
  return t[0] == u[0] || t[0] == u[1] || t[0] == u[2] || t[1] == u[0] || t[1] == u[1] || t[1] == u[2] || t[2] == u[0] ||
         t[2] == u[1] || t[2] == u[2];
}

/** A uniform grid of axis-aligned boxes (one per triangle, 6 floats: lower
 * x, y, z, upper x, y, z), hashed into buckets: ForEachOverlap() visits, for
 * one box, every other box that overlaps it, once. */
class BoxGrid
{
public:
  /** Builds the grid over \a numberOfBoxes boxes; cell size: the mean of the
   * boxes' largest extents (each box is entered in every cell it overlaps). */
  void
  Build(const float * boxes, SizeValueType numberOfBoxes)
  {
    m_Boxes = boxes;
    m_NumberOfBoxes = numberOfBoxes;
    double extent = 0.0;
    double lower[3] = { std::numeric_limits<double>::infinity(),
                        std::numeric_limits<double>::infinity(),
                        std::numeric_limits<double>::infinity() };
    for (SizeValueType t = 0; t < numberOfBoxes; ++t)
    {
      const float * b = boxes + 6 * t;
      extent += std::max({ b[3] - b[0], b[4] - b[1], b[5] - b[2] });
      for (unsigned int k = 0; k < 3; ++k)
      {
        lower[k] = std::min(lower[k], static_cast<double>(b[k]));
      }
    }
    m_CellSize = numberOfBoxes > 0 ? extent / static_cast<double>(numberOfBoxes) : 1.0;
    if (!(m_CellSize > 0.0) || !std::isfinite(m_CellSize))
    {
      m_CellSize = 1.0;
    }
    for (unsigned int k = 0; k < 3; ++k)
    {
      m_Origin[k] = std::isfinite(lower[k]) ? lower[k] : 0.0;
    }
    m_InverseCellSize = 1.0 / m_CellSize;

    SizeValueType entries = 0;
    for (SizeValueType t = 0; t < numberOfBoxes; ++t)
    {
      int64_t lo[3], hi[3];
      this->CellRange(boxes + 6 * t, lo, hi);
      entries += static_cast<SizeValueType>((hi[0] - lo[0] + 1) * (hi[1] - lo[1] + 1) * (hi[2] - lo[2] + 1));
    }
    SizeValueType buckets = 1;
    while (buckets < entries + 1)
    {
      buckets *= 2;
    }
    m_Mask = buckets - 1;
    m_BucketOffsets.assign(buckets + 1, 0);
    const auto forEachCell = [this](const float * box, auto && f) {
      int64_t lo[3], hi[3];
      this->CellRange(box, lo, hi);
      for (int64_t k = lo[2]; k <= hi[2]; ++k)
      {
        for (int64_t j = lo[1]; j <= hi[1]; ++j)
        {
          for (int64_t i = lo[0]; i <= hi[0]; ++i)
          {
            f(this->Bucket(i, j, k));
          }
        }
      }
    };
    // A box whose cells hash alike is entered once in their bucket: its
    // entries in one bucket would be consecutive.
    std::vector<uint32_t> last(buckets, std::numeric_limits<uint32_t>::max());
    for (SizeValueType t = 0; t < numberOfBoxes; ++t)
    {
      forEachCell(boxes + 6 * t, [&](SizeValueType bucket) {
        if (last[bucket] != t)
        {
          last[bucket] = static_cast<uint32_t>(t);
          ++m_BucketOffsets[bucket + 1];
        }
      });
    }
    std::fill(last.begin(), last.end(), std::numeric_limits<uint32_t>::max());
    for (SizeValueType b = 0; b < buckets; ++b)
    {
      m_BucketOffsets[b + 1] += m_BucketOffsets[b];
    }
    m_Entries.resize(m_BucketOffsets[buckets]);
    std::vector<SizeValueType> fill(m_BucketOffsets.begin(), m_BucketOffsets.end() - 1);
    for (SizeValueType t = 0; t < numberOfBoxes; ++t)
    {
      forEachCell(boxes + 6 * t, [&](SizeValueType bucket) {
        if (last[bucket] != t)
        {
          last[bucket] = static_cast<uint32_t>(t);
          m_Entries[fill[bucket]++] = static_cast<uint32_t>(t);
        }
      });
    }
  }

  /** Calls f(u) for every box u != t that overlaps box t, once each. */
  template <typename TFunction>
  void
  ForEachOverlap(SizeValueType t, TFunction && f) const
  {
    const float * a = m_Boxes + 6 * t;
    int64_t       lo[3], hi[3];
    this->CellRange(a, lo, hi);
    for (int64_t k = lo[2]; k <= hi[2]; ++k)
    {
      for (int64_t j = lo[1]; j <= hi[1]; ++j)
      {
        for (int64_t i = lo[0]; i <= hi[0]; ++i)
        {
          const SizeValueType bucket = this->Bucket(i, j, k);
          const uint32_t *    begin = m_Entries.data() + m_BucketOffsets[bucket];
          const uint32_t *    end = m_Entries.data() + m_BucketOffsets[bucket + 1];
          for (const uint32_t * e = begin; e != end; ++e)
          {
            const SizeValueType u = *e;
            if (u == t)
            {
              continue;
            }
            const float * b = m_Boxes + 6 * u;
            if (a[0] > b[3] || b[0] > a[3] || a[1] > b[4] || b[1] > a[4] || a[2] > b[5] || b[2] > a[5])
            {
              continue;
            }
            // Visit the pair in one cell only: the one that holds the lower
            // corner of the boxes' intersection.
            const int64_t ci = this->CellOf(std::max(a[0], b[0]), 0);
            const int64_t cj = this->CellOf(std::max(a[1], b[1]), 1);
            const int64_t ck = this->CellOf(std::max(a[2], b[2]), 2);
            if (ci != i || cj != j || ck != k)
            {
              continue;
            }
            f(u);
          }
        }
      }
    }
  }

  SizeValueType
  GetNumberOfEntries() const
  {
    return m_Entries.size();
  }

  void
  Clear()
  {
    std::vector<SizeValueType>().swap(m_BucketOffsets);
    std::vector<uint32_t>().swap(m_Entries);
    m_Boxes = nullptr;
    m_NumberOfBoxes = 0;
  }

private:
  int64_t
  CellOf(double x, unsigned int axis) const
  {
    // Every box lies above the origin (the lowest corner): truncation is
    // the floor.
    return static_cast<int64_t>((x - m_Origin[axis]) * m_InverseCellSize);
  }

  void
  CellRange(const float * box, int64_t * lo, int64_t * hi) const
  {
    for (unsigned int k = 0; k < 3; ++k)
    {
      lo[k] = this->CellOf(box[k], k);
      hi[k] = this->CellOf(box[3 + k], k);
    }
  }

  SizeValueType
  Bucket(int64_t i, int64_t j, int64_t k) const
  {
    const uint64_t h = static_cast<uint64_t>(i) * 0x9E3779B185EBCA87ULL ^
                       static_cast<uint64_t>(j) * 0xC2B2AE3D27D4EB4FULL ^
                       static_cast<uint64_t>(k) * 0x165667B19E3779F9ULL;
    return static_cast<SizeValueType>((h ^ (h >> 29)) & m_Mask);
  }

  const float *              m_Boxes{ nullptr };
  SizeValueType              m_NumberOfBoxes{ 0 };
  double                     m_CellSize{ 1.0 };
  double                     m_InverseCellSize{ 1.0 };
  double                     m_Origin[3]{};
  uint64_t                   m_Mask{ 0 };
  std::vector<SizeValueType> m_BucketOffsets;
  std::vector<uint32_t>      m_Entries;
};

/** Writes the float box of the points (3 doubles each) given, widened by
 * \a margin and rounded outward. */
inline void
StoreBox(const double * lower, const double * upper, double margin, float * box)
{
  for (unsigned int k = 0; k < 3; ++k)
  {
    const double lo = lower[k] - margin;
    const double hi = upper[k] + margin;
    float        flo = static_cast<float>(lo);
    float        fhi = static_cast<float>(hi);
    if (static_cast<double>(flo) > lo)
    {
      flo = std::nextafter(flo, -std::numeric_limits<float>::infinity());
    }
    if (static_cast<double>(fhi) < hi)
    {
      fhi = std::nextafter(fhi, std::numeric_limits<float>::infinity());
    }
    box[k] = flo;
    box[3 + k] = fhi;
  }
}
} // namespace SurfaceCollisionDetail

/** \class SurfaceCollision
 * \brief Keeps a moving triangulated surface from intersecting itself:
 * finds the pairs of triangles sharing no vertex that intersect or come
 * closer than a minimum distance, and reduces the displacements of their
 * vertices until every pair is clear.
 *
 * Works on flat arrays: point coordinates (3 doubles a point, physical
 * units) and triangles (3 point indices each). Pairs of triangles that share
 * a vertex are never tested (they touch by construction).
 *
 * Constrain() takes the current positions x (a state in which no pair
 * intersects) and the proposed next positions y, and modifies y. A pair
 * (A, B) violates the constraint at y when their distance is below the
 * minimum distance d and below their distance at x: a pair that was already
 * closer than d may stay so but not come closer, and from a state without
 * intersection (distance 0) none is created. The vertices of violating pairs get their displacements halved,
 * at the next violation halved again, at the third set to zero; the pairs of
 * every modified triangle are tested again until none violates. This
 * terminates (at worst every displacement is zero, which gives back x) and
 * the result is a state in which no pair that did not intersect at x
 * intersects, and no pair that was at least d apart is closer than d.
 *
 * The spatial index: each point i has a reference position r_i (x at the
 * last rebuild) and a box it may move in: the box swept by its displacement
 * y_i - x_i of that step and two more of the same, widened by a quarter of
 * the mean edge length. A triangle's box is the union of its points' boxes,
 * widened by d/2; the boxes are entered in a uniform hashed grid. Two
 * triangles whose boxes do not overlap are more than d apart as long as
 * every point stays in its box. Each triangle also keeps a clearance: a
 * lower bound of its distance at the reference positions to the triangles
 * whose boxes overlap its own, less d (bounding spheres; the exact distance
 * where the spheres are close). At each Constrain() the motion
 * m_i = max(|x_i - r_i|, |y_i - r_i|) of every point is computed; where some
 * y_i leaves its box, the index is rebuilt at x. Only the triangles whose
 * motion m_T (largest of their points') plus the largest motion M of all
 * points reaches their clearance are tested, against the triangles of the
 * grid near them: on a surface that has settled, a step costs a pass over
 * the points and one over the triangles; a surface that moves fast rebuilds
 * the index every two or three steps.
 *
 * CountSelfIntersections() counts the intersecting pairs of a surface with
 * the same grid (exact triangle boxes).
 *
 * \ingroup ExplicitDeformableModel
 */
class SurfaceCollision
{
public:
  using IndexType = uint32_t;

  /** Statistics of one Constrain(). */
  struct Result
  {
    SizeValueType violations{ 0 };  // violating pairs found (each time one is found)
    SizeValueType constrained{ 0 }; // points whose displacement was reduced
    bool          rebuilt{ false }; // the index was rebuilt
  };

  /** Sets the surface's connectivity: \a numberOfTriangles triangles of 3
   * point indices (< numberOfPoints) each. Drops the spatial index; the next
   * Constrain() builds it. Call again whenever the mesh changes (remeshing,
   * renumbering). */
  void
  SetSurface(SizeValueType numberOfPoints, const IndexType * triangles, SizeValueType numberOfTriangles)
  {
    m_NumberOfPoints = numberOfPoints;
    m_Triangles.assign(triangles, triangles + 3 * numberOfTriangles);
    m_VertexTriangleOffsets.assign(numberOfPoints + 1, 0);
    for (const IndexType v : m_Triangles)
    {
      ++m_VertexTriangleOffsets[v + 1];
    }
    for (SizeValueType i = 0; i < numberOfPoints; ++i)
    {
      m_VertexTriangleOffsets[i + 1] += m_VertexTriangleOffsets[i];
    }
    m_VertexTriangles.resize(m_Triangles.size());
    std::vector<SizeValueType> fill(m_VertexTriangleOffsets.begin(), m_VertexTriangleOffsets.end() - 1);
    for (SizeValueType t = 0; t < numberOfTriangles; ++t)
    {
      for (unsigned int k = 0; k < 3; ++k)
      {
        m_VertexTriangles[fill[m_Triangles[3 * t + k]]++] = static_cast<IndexType>(t);
      }
    }
    m_HasSurface = true;
    this->Invalidate();
  }

  /** Forgets the connectivity and the index. */
  void
  Clear()
  {
    *this = SurfaceCollision();
  }

  bool
  HasSurface() const
  {
    return m_HasSurface;
  }

  /** Drops the spatial index (the next Constrain() rebuilds it), for
   * example when the positions were changed outside Constrain(). */
  void
  Invalidate()
  {
    m_IndexValid = false;
  }

  SizeValueType
  GetNumberOfPoints() const
  {
    return m_NumberOfPoints;
  }
  SizeValueType
  GetNumberOfTriangles() const
  {
    return m_Triangles.size() / 3;
  }
  const std::vector<IndexType> &
  GetTriangles() const
  {
    return m_Triangles;
  }

  /** Number of index rebuilds since SetSurface(). */
  SizeValueType
  GetNumberOfRebuilds() const
  {
    return m_NumberOfRebuilds;
  }

  /** The points whose displacement the last Constrain() reduced. */
  const std::vector<IndexType> &
  GetConstrainedPoints() const
  {
    return m_ModifiedPoints;
  }

  /** Distance below which two triangles count as touching whatever the
   * minimum distance: 1e-6 of the mean edge length (set at each rebuild). */
  double
  GetContactDistance() const
  {
    return m_ContactDistance;
  }

  /** Modifies the proposed positions \a y (3 doubles a point) so that no
   * pair of triangles sharing no vertex violates the constraint described
   * in the class documentation, given the current positions \a x, clear.
   * \a minimumDistance is in the units of the coordinates, >= 0.
   * \a threader (may be null) runs the passes over \a workUnits units. */
  Result
  Constrain(const double * x, double * y, double minimumDistance, MultiThreaderBase * threader, unsigned int workUnits)
  {
    Result              result;
    const SizeValueType n = m_NumberOfPoints;
    const SizeValueType numberOfTriangles = this->GetNumberOfTriangles();
    m_ModifiedPoints.clear();
    if (n == 0 || numberOfTriangles < 2)
    {
      return result;
    }
    if (m_Motion.size() != n)
    {
      m_Motion.assign(n, 0.0f);
      m_Level.assign(n, 0);
      m_IndexValid = false;
    }
    if (m_IndexValid && minimumDistance != m_MinimumDistance)
    {
      m_IndexValid = false;
    }
    const auto parallel = [threader, workUnits](SizeValueType count, auto && body) {
      constexpr SizeValueType block = 4096;
      const SizeValueType     blocks = (count + block - 1) / block;
      const auto              run = [&](SizeValueType b) { body(b * block, std::min(count, (b + 1) * block)); };
      if (threader == nullptr || blocks < 2 || workUnits < 2)
      {
        for (SizeValueType b = 0; b < blocks; ++b)
        {
          run(b);
        }
      }
      else
      {
        threader->SetNumberOfWorkUnits(workUnits);
        threader->ParallelizeArray(0, blocks, run, nullptr);
      }
    };

    // Motion of every point since the reference positions; a point out of
    // its box makes the index be rebuilt.
    float largest = 0.0f;
    if (m_IndexValid)
    {
      std::atomic<bool>  escaped{ false };
      std::atomic<bool>  nonFinite{ false };
      std::vector<float> blockLargest((n + 4095) / 4096, 0.0f);
      parallel(n, [&](SizeValueType begin, SizeValueType end) {
        float top = 0.0f;
        bool  out = false;
        for (SizeValueType i = begin; i < end; ++i)
        {
          const double * r = m_Reference.data() + 3 * i;
          const double * p = x + 3 * i;
          const double * q = y + 3 * i;
          const double   a =
            (p[0] - r[0]) * (p[0] - r[0]) + (p[1] - r[1]) * (p[1] - r[1]) + (p[2] - r[2]) * (p[2] - r[2]);
          const double b =
            (q[0] - r[0]) * (q[0] - r[0]) + (q[1] - r[1]) * (q[1] - r[1]) + (q[2] - r[2]) * (q[2] - r[2]);
          const double m = std::sqrt(std::max(a, b));
          const float  mf = RoundUp(m);
          m_Motion[i] = mf;
          top = std::max(top, mf);
          const float * box = m_VertexBoxes.data() + 6 * i;
          out = out || !(box[0] <= q[0] && q[0] <= box[3] && box[1] <= q[1] && q[1] <= box[4] && box[2] <= q[2] &&
                         q[2] <= box[5]);
          if (!std::isfinite(m))
          {
            nonFinite = true;
          }
        }
        blockLargest[begin / 4096] = top;
        if (out)
        {
          escaped = true;
        }
      });
      if (nonFinite)
      {
        return result; // a diverged step: the filter reports it
      }
      largest = *std::max_element(blockLargest.begin(), blockLargest.end());
      if (escaped)
      {
        m_IndexValid = false;
      }
    }
    const SizeValueType                                       blocks = (numberOfTriangles + 4095) / 4096;
    std::vector<std::vector<std::pair<IndexType, IndexType>>> found(blocks);
    const bool                                                rebuild = !m_IndexValid;
    if (rebuild)
    {
      // The rebuild tests the pairs that may violate as it computes the
      // clearances.
      if (!this->Build(x, y, minimumDistance, parallel, found))
      {
        return result; // a diverged step: the filter reports it
      }
      result.rebuilt = true;
      largest = *std::max_element(m_Motion.begin(), m_Motion.end());
    }
    const double d = std::max(minimumDistance, m_ContactDistance);

    // Triangles that may violate: their motion plus the largest motion reach
    // their clearance; the pairs of two active triangles are tested by the
    // one of lower index, those whose bound at the reference less d exceeds
    // the two triangles' motions not at all.
    if (!rebuild)
    {
      m_Active.resize(numberOfTriangles);
      parallel(numberOfTriangles, [&](SizeValueType begin, SizeValueType end) {
        for (SizeValueType t = begin; t < end; ++t)
        {
          const IndexType * v = m_Triangles.data() + 3 * t;
          const float       mt = std::max({ m_Motion[v[0]], m_Motion[v[1]], m_Motion[v[2]] });
          m_TriangleMotion[t] = mt;
          m_Active[t] = mt > 0.0f && static_cast<double>(mt) + static_cast<double>(largest) >= m_Clearance[t];
        }
      });
      parallel(numberOfTriangles, [&](SizeValueType begin, SizeValueType end) {
        auto & out = found[begin / 4096];
        for (SizeValueType t = begin; t < end; ++t)
        {
          if (!m_Active[t])
          {
            continue;
          }
          const double * st = m_Spheres.data() + 4 * t;
          m_Grid.ForEachOverlap(t, [&](SizeValueType u) {
            if ((m_Active[u] && u < t) ||
                SurfaceCollisionDetail::ShareVertex(m_Triangles.data() + 3 * t, m_Triangles.data() + 3 * u))
            {
              return;
            }
            const double * su = m_Spheres.data() + 4 * u;
            double         e[3];
            SurfaceCollisionDetail::Subtract(st, su, e);
            if (std::sqrt(SurfaceCollisionDetail::Dot(e, e)) - st[3] - su[3] - d >
                static_cast<double>(m_TriangleMotion[t]) + static_cast<double>(m_TriangleMotion[u]))
            {
              return;
            }
            if (this->Violates(t, u, x, y, d))
            {
              out.emplace_back(static_cast<IndexType>(std::min(t, u)), static_cast<IndexType>(std::max(t, u)));
            }
          });
        }
      });
    }
    std::vector<std::pair<IndexType, IndexType>> violating;
    for (const auto & block : found)
    {
      violating.insert(violating.end(), block.begin(), block.end());
    }

    // Reduce the displacements of the violating pairs' points, test the
    // pairs of the modified triangles again, until none violates.
    std::vector<IndexType> touched;
    std::vector<IndexType> triangles;
    while (!violating.empty())
    {
      std::sort(violating.begin(), violating.end());
      violating.erase(std::unique(violating.begin(), violating.end()), violating.end());
      result.violations += violating.size();
      touched.clear();
      for (const auto & pair : violating)
      {
        for (const IndexType t : { pair.first, pair.second })
        {
          for (unsigned int k = 0; k < 3; ++k)
          {
            touched.push_back(m_Triangles[3 * t + k]);
          }
        }
      }
      std::sort(touched.begin(), touched.end());
      touched.erase(std::unique(touched.begin(), touched.end()), touched.end());
      triangles.clear();
      for (const IndexType i : touched)
      {
        if (m_Level[i] == 0)
        {
          m_ModifiedPoints.push_back(i);
        }
        if (m_Level[i] >= 3)
        {
          continue; // already at x
        }
        ++m_Level[i];
        double *       q = y + 3 * i;
        const double * p = x + 3 * i;
        for (unsigned int k = 0; k < 3; ++k)
        {
          q[k] = m_Level[i] >= 3 ? p[k] : p[k] + 0.5 * (q[k] - p[k]);
        }
        triangles.insert(triangles.end(),
                         m_VertexTriangles.begin() + m_VertexTriangleOffsets[i],
                         m_VertexTriangles.begin() + m_VertexTriangleOffsets[i + 1]);
      }
      std::sort(triangles.begin(), triangles.end());
      triangles.erase(std::unique(triangles.begin(), triangles.end()), triangles.end());
      violating.clear();
      for (const IndexType t : triangles)
      {
        m_Grid.ForEachOverlap(t, [&](SizeValueType u) {
          if (SurfaceCollisionDetail::ShareVertex(m_Triangles.data() + 3 * t, m_Triangles.data() + 3 * u))
          {
            return;
          }
          if (this->Violates(t, u, x, y, d))
          {
            violating.emplace_back(std::min<IndexType>(t, static_cast<IndexType>(u)),
                                   std::max<IndexType>(t, static_cast<IndexType>(u)));
          }
        });
      }
    }
    for (const IndexType i : m_ModifiedPoints)
    {
      m_Level[i] = 0;
    }
    result.constrained = m_ModifiedPoints.size();
    return result;
  }

  /** Counts the pairs of triangles sharing no vertex that intersect
   * (TrianglesIntersect()); the first pair (lowest first triangle, then
   * lowest second) in \a first when not null ({-1, -1} when none).
   * \a x: 3 doubles a point; \a triangles: 3 point indices each. */
  static SizeValueType
  CountSelfIntersections(const double *                            x,
                         const IndexType *                         triangles,
                         SizeValueType                             numberOfTriangles,
                         std::pair<SizeValueType, SizeValueType> * first = nullptr)
  {
    std::vector<float> boxes(6 * numberOfTriangles);
    for (SizeValueType t = 0; t < numberOfTriangles; ++t)
    {
      double lo[3], hi[3];
      TriangleBox(x, triangles + 3 * t, lo, hi);
      SurfaceCollisionDetail::StoreBox(lo, hi, 0.0, boxes.data() + 6 * t);
    }
    SurfaceCollisionDetail::BoxGrid grid;
    grid.Build(boxes.data(), numberOfTriangles);
    SizeValueType                           count = 0;
    const auto                              none = std::numeric_limits<SizeValueType>::max();
    std::pair<SizeValueType, SizeValueType> firstPair(none, none);
    for (SizeValueType t = 0; t < numberOfTriangles; ++t)
    {
      grid.ForEachOverlap(t, [&](SizeValueType u) {
        if (u < t || SurfaceCollisionDetail::ShareVertex(triangles + 3 * t, triangles + 3 * u))
        {
          return;
        }
        const double * a[3] = { x + 3 * triangles[3 * t], x + 3 * triangles[3 * t + 1], x + 3 * triangles[3 * t + 2] };
        const double * b[3] = { x + 3 * triangles[3 * u], x + 3 * triangles[3 * u + 1], x + 3 * triangles[3 * u + 2] };
        if (SurfaceCollisionDetail::TrianglesIntersect(a, b))
        {
          ++count;
          firstPair = std::min(firstPair, std::make_pair(t, u));
        }
      });
    }
    if (first != nullptr)
    {
      *first = firstPair;
    }
    return count;
  }

  /** The triangles of a mesh's cells: triangles as they are, polygons and
   * quadrilaterals fan-triangulated (a, b, c), (a, c, d), ...; other cells
   * ignored. \a cells (may be null) receives the cell identifier of each
   * triangle. */
  template <typename TMesh>
  static void
  ExtractTriangles(const TMesh * mesh, std::vector<IndexType> & triangles, std::vector<SizeValueType> * cells = nullptr)
  {
    triangles.clear();
    if (cells != nullptr)
    {
      cells->clear();
    }
    if (mesh == nullptr || mesh->GetCells() == nullptr)
    {
      return;
    }
    for (auto it = mesh->GetCells()->Begin(); it != mesh->GetCells()->End(); ++it)
    {
      const auto * cell = it.Value();
      const auto   type = cell->GetType();
      if (type != CommonEnums::CellGeometry::TRIANGLE_CELL && type != CommonEnums::CellGeometry::QUADRILATERAL_CELL &&
          type != CommonEnums::CellGeometry::POLYGON_CELL)
      {
        continue;
      }
      const auto   n = static_cast<unsigned int>(cell->GetNumberOfPoints());
      const auto * ids = cell->PointIdsBegin();
      for (unsigned int k = 1; k + 1 < n; ++k)
      {
        triangles.push_back(static_cast<IndexType>(ids[0]));
        triangles.push_back(static_cast<IndexType>(ids[k]));
        triangles.push_back(static_cast<IndexType>(ids[k + 1]));
        if (cells != nullptr)
        {
          cells->push_back(static_cast<SizeValueType>(it.Index()));
        }
      }
    }
  }

  /** Number of intersecting pairs of triangles sharing no vertex of a mesh
   * (itk::Mesh or any mesh with the same interface: triangles and
   * fan-triangulated polygons), for quality reports. */
  template <typename TMesh>
  static SizeValueType
  CountSelfIntersections(const TMesh * mesh)
  {
    std::vector<IndexType> triangles;
    ExtractTriangles(mesh, triangles);
    std::vector<double> x;
    x.reserve(3 * mesh->GetNumberOfPoints());
    for (auto it = mesh->GetPoints()->Begin(); it != mesh->GetPoints()->End(); ++it)
    {
      for (unsigned int k = 0; k < 3; ++k)
      {
        x.push_back(static_cast<double>(it.Value()[k]));
      }
    }
    return CountSelfIntersections(x.data(), triangles.data(), triangles.size() / 3);
  }

private:
  static void
  TriangleBox(const double * x, const IndexType * v, double * lo, double * hi)
  {
    for (unsigned int k = 0; k < 3; ++k)
    {
      lo[k] = std::min({ x[3 * v[0] + k], x[3 * v[1] + k], x[3 * v[2] + k] });
      hi[k] = std::max({ x[3 * v[0] + k], x[3 * v[1] + k], x[3 * v[2] + k] });
    }
  }

  /** Pair (t, u) violates at y (see the class documentation); d > 0. */
  bool
  Violates(SizeValueType t, SizeValueType u, const double * x, const double * y, double d) const
  {
    const IndexType * vt = m_Triangles.data() + 3 * t;
    const IndexType * vu = m_Triangles.data() + 3 * u;
    double            lt[3], ht[3], lu[3], hu[3];
    TriangleBox(y, vt, lt, ht);
    TriangleBox(y, vu, lu, hu);
    for (unsigned int k = 0; k < 3; ++k)
    {
      if (lt[k] - hu[k] >= d || lu[k] - ht[k] >= d)
      {
        return false;
      }
    }
    double st[4], su[4], e[3];
    Sphere(y, vt, st);
    Sphere(y, vu, su);
    SurfaceCollisionDetail::Subtract(st, su, e);
    if (std::sqrt(SurfaceCollisionDetail::Dot(e, e)) - st[3] - su[3] >= d * (1.0 + 1e-12))
    {
      return false;
    }
    const double * a[3] = { y + 3 * vt[0], y + 3 * vt[1], y + 3 * vt[2] };
    const double * b[3] = { y + 3 * vu[0], y + 3 * vu[1], y + 3 * vu[2] };
    const double   next = SurfaceCollisionDetail::TriangleDistance(a, b);
    if (next >= d)
    {
      return false;
    }
    const double * a0[3] = { x + 3 * vt[0], x + 3 * vt[1], x + 3 * vt[2] };
    const double * b0[3] = { x + 3 * vu[0], x + 3 * vu[1], x + 3 * vu[2] };
    return next < SurfaceCollisionDetail::TriangleDistance(a0, b0);
  }

  /** Rebuilds the index at the reference positions x: the points' boxes
   * from the proposed displacements y - x, motions |y - x|, clearances.
   * False (and nothing built) when a coordinate is not finite. */
  template <typename TParallel>
  bool
  Build(const double *                                              x,
        const double *                                              y,
        double                                                      minimumDistance,
        TParallel &&                                                parallel,
        std::vector<std::vector<std::pair<IndexType, IndexType>>> & found)
  {
    const SizeValueType n = m_NumberOfPoints;
    const SizeValueType numberOfTriangles = this->GetNumberOfTriangles();
    ++m_NumberOfRebuilds;
    m_MinimumDistance = minimumDistance;
    double edges = 0.0;
    for (SizeValueType t = 0; t < numberOfTriangles; ++t)
    {
      const IndexType * v = m_Triangles.data() + 3 * t;
      for (unsigned int k = 0; k < 3; ++k)
      {
        double e[3];
        SurfaceCollisionDetail::Subtract(x + 3 * v[k], x + 3 * v[(k + 1) % 3], e);
        edges += std::sqrt(SurfaceCollisionDetail::Dot(e, e));
      }
    }
    const double meanEdge = edges / static_cast<double>(3 * numberOfTriangles);
    m_ContactDistance = 1e-6 * meanEdge;
    const double d = std::max(minimumDistance, m_ContactDistance);
    const double baseSkin = 0.25 * meanEdge;
    m_Reference.assign(x, x + 3 * n);
    m_VertexBoxes.resize(6 * n);
    std::atomic<bool> finite{ std::isfinite(meanEdge) };
    parallel(n, [&](SizeValueType begin, SizeValueType end) {
      bool blockFinite = true;
      for (SizeValueType i = begin; i < end; ++i)
      {
        double e[3];
        SurfaceCollisionDetail::Subtract(y + 3 * i, x + 3 * i, e);
        const double m = std::sqrt(SurfaceCollisionDetail::Dot(e, e));
        blockFinite = blockFinite && std::isfinite(m);
        m_Motion[i] = RoundUp(m);
        // The box swept by this step and one more of the same displacement,
        // widened by the base skin.
        double lo[3], hi[3];
        for (unsigned int k = 0; k < 3; ++k)
        {
          const double ahead = x[3 * i + k] + 2.0 * e[k];
          lo[k] = std::min(x[3 * i + k], ahead);
          hi[k] = std::max(x[3 * i + k], ahead);
        }
        SurfaceCollisionDetail::StoreBox(lo, hi, baseSkin, m_VertexBoxes.data() + 6 * i);
      }
      if (!blockFinite)
      {
        finite = false;
      }
    });
    if (!finite)
    {
      m_IndexValid = false;
      return false;
    }
    m_Boxes.resize(6 * numberOfTriangles);
    m_TriangleMotion.resize(numberOfTriangles);
    m_Active.assign(numberOfTriangles, 0);
    parallel(numberOfTriangles, [&](SizeValueType begin, SizeValueType end) {
      for (SizeValueType t = begin; t < end; ++t)
      {
        const IndexType * v = m_Triangles.data() + 3 * t;
        m_TriangleMotion[t] = std::max({ m_Motion[v[0]], m_Motion[v[1]], m_Motion[v[2]] });
        double lo[3], hi[3];
        for (unsigned int k = 0; k < 3; ++k)
        {
          lo[k] = std::min({ m_VertexBoxes[6 * v[0] + k], m_VertexBoxes[6 * v[1] + k], m_VertexBoxes[6 * v[2] + k] });
          hi[k] = std::max(
            { m_VertexBoxes[6 * v[0] + 3 + k], m_VertexBoxes[6 * v[1] + 3 + k], m_VertexBoxes[6 * v[2] + 3 + k] });
        }
        SurfaceCollisionDetail::StoreBox(lo, hi, 0.5 * d, m_Boxes.data() + 6 * t);
      }
    });
    m_Grid.Build(m_Boxes.data(), numberOfTriangles);

    // Clearances: lower bounds, at x, of the distances to the triangles
    // whose boxes overlap, less d: bounding spheres (centroid, largest
    // distance to a vertex), the exact distance where the spheres' gap less
    // d is below the base skin.
    m_Clearance.resize(numberOfTriangles);
    m_Spheres.resize(4 * numberOfTriangles);
    parallel(numberOfTriangles, [&](SizeValueType begin, SizeValueType end) {
      for (SizeValueType t = begin; t < end; ++t)
      {
        Sphere(x, m_Triangles.data() + 3 * t, m_Spheres.data() + 4 * t);
      }
    });
    parallel(numberOfTriangles, [&](SizeValueType begin, SizeValueType end) {
      auto & out = found[begin / 4096];
      for (SizeValueType t = begin; t < end; ++t)
      {
        const IndexType * vt = m_Triangles.data() + 3 * t;
        const double *    st = m_Spheres.data() + 4 * t;
        double            clearance = std::numeric_limits<double>::infinity();
        m_Grid.ForEachOverlap(t, [&](SizeValueType u) {
          const IndexType * vu = m_Triangles.data() + 3 * u;
          if (SurfaceCollisionDetail::ShareVertex(vt, vu))
          {
            return;
          }
          const double * su = m_Spheres.data() + 4 * u;
          double         e[3];
          SurfaceCollisionDetail::Subtract(st, su, e);
          double bound = std::sqrt(SurfaceCollisionDetail::Dot(e, e)) - st[3] - su[3];
          if (bound - d < baseSkin)
          {
            const double * a[3] = { x + 3 * vt[0], x + 3 * vt[1], x + 3 * vt[2] };
            const double * b[3] = { x + 3 * vu[0], x + 3 * vu[1], x + 3 * vu[2] };
            bound = std::max(bound, SurfaceCollisionDetail::TriangleDistance(a, b));
          }
          clearance = std::min(clearance, bound - d);
          if (t < u &&
              bound - d <= static_cast<double>(m_TriangleMotion[t]) + static_cast<double>(m_TriangleMotion[u]) &&
              this->Violates(t, u, x, y, d))
          {
            out.emplace_back(static_cast<IndexType>(t), static_cast<IndexType>(u));
          }
        });
        m_Clearance[t] = clearance;
      }
    });
    m_IndexValid = true;
    return true;
  }

  /** m as a float not below it (0 stays 0). */
  static float
  RoundUp(double m)
  {
    const float f = static_cast<float>(m);
    return static_cast<double>(f) >= m ? f : std::nextafter(f, std::numeric_limits<float>::infinity());
  }

  /** Bounding sphere of a triangle: centroid c[0..2], radius c[3] (the
   * largest distance to a vertex). */
  static void
  Sphere(const double * x, const IndexType * v, double * c)
  {
    for (unsigned int k = 0; k < 3; ++k)
    {
      c[k] = (x[3 * v[0] + k] + x[3 * v[1] + k] + x[3 * v[2] + k]) / 3.0;
    }
    double r2 = 0.0;
    for (unsigned int j = 0; j < 3; ++j)
    {
      double e[3];
      SurfaceCollisionDetail::Subtract(x + 3 * v[j], c, e);
      r2 = std::max(r2, SurfaceCollisionDetail::Dot(e, e));
    }
    // Widened by a relative 1e-12: a bound whatever the rounding.
    c[3] = std::sqrt(r2) * (1.0 + 1e-12);
  }

  SizeValueType              m_NumberOfPoints{ 0 };
  bool                       m_HasSurface{ false };
  std::vector<IndexType>     m_Triangles;
  std::vector<SizeValueType> m_VertexTriangleOffsets;
  std::vector<IndexType>     m_VertexTriangles;

  // The index: reference positions, points' and triangles' boxes, grid,
  // clearances.
  bool                            m_IndexValid{ false };
  double                          m_MinimumDistance{ 0.0 };
  double                          m_ContactDistance{ 0.0 };
  SizeValueType                   m_NumberOfRebuilds{ 0 };
  std::vector<double>             m_Reference;
  std::vector<float>              m_VertexBoxes; // per point: the box it may move in
  std::vector<double>             m_Spheres;     // per triangle at the reference: centre, radius
  std::vector<float>              m_Boxes;
  std::vector<double>             m_Clearance;
  SurfaceCollisionDetail::BoxGrid m_Grid;

  // Per step.
  std::vector<float>     m_Motion;
  std::vector<uint8_t>   m_Active;
  std::vector<float>     m_TriangleMotion; // largest motion of its points
  std::vector<uint8_t>   m_Level;
  std::vector<IndexType> m_ModifiedPoints;
};
} // end namespace itk

#endif
