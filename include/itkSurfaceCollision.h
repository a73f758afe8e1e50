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
#include <array>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <numeric>
#include <utility>
#include <vector>
#if defined(__SSE2__)
#  include <emmintrin.h>
#endif

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

/** Exact signs of the orientation determinants. A floating-point
 * evaluation decides when its magnitude exceeds a bound of its rounding
 * error (the usual case); otherwise the determinant is summed exactly as an
 * expansion (a sum of non-overlapping doubles, error-free transformations:
 * TwoSum and the fused multiply-add's TwoProduct), so that nearly coplanar
 * points (a flat patch of a subdivided mesh, which the plain determinants
 * call crossing or not at random) get their true sign. */
class ExactSum
{
public:
  /** Adds a double exactly (Grow-Expansion with zero elimination). */
  void
  Add(double b)
  {
    double      q = b;
    std::size_t kept = 0;
    for (std::size_t i = 0; i < m_Terms.size(); ++i)
    {
      const double e = m_Terms[i];
      const double sum = q + e;
      const double bv = sum - q;
      const double av = sum - bv;
      const double low = (q - av) + (e - bv);
      q = sum;
      if (low != 0.0)
      {
        m_Terms[kept++] = low;
      }
    }
    m_Terms.resize(kept);
    if (q != 0.0)
    {
      m_Terms.push_back(q);
    }
  }

  /** Adds the exact product p q r (four doubles). */
  void
  AddProduct(double p, double q, double r)
  {
    const double hi = p * q;
    const double lo = std::fma(p, q, -hi);
    for (const double s : { hi, lo })
    {
      const double h = s * r;
      this->Add(std::fma(s, r, -h));
      this->Add(h);
    }
  }

  /** Sign of the sum: that of its largest term. */
  int
  Sign() const
  {
    return m_Terms.empty() ? 0 : (m_Terms.back() > 0.0 ? 1 : -1);
  }

private:
  std::vector<double> m_Terms; // non-zero, non-overlapping, of increasing magnitude
};

/** b - a exactly as hi + lo. */
inline void
TwoDifference(double b, double a, double & hi, double & lo)
{
  hi = b - a;
  const double bv = b - hi;
  const double av = hi + bv;
  lo = (b - av) + (bv - a);
}

/** The floating-point filter of Orient3DSign(): the sign of the
 * determinant of the rounded differences ab = b - a, ac = c - a, ad = d - a
 * when its error bound decides it, else 0 (undecided; also for values that
 * are not finite). */
inline int
Orient3DFilteredSign(const double * ab, const double * ac, const double * ad)
{
  const double m0 = ab[1] * ac[2] - ab[2] * ac[1];
  const double m1 = ab[2] * ac[0] - ab[0] * ac[2];
  const double m2 = ab[0] * ac[1] - ab[1] * ac[0];
  const double det = m0 * ad[0] + m1 * ad[1] + m2 * ad[2];
  const double permanent = (std::abs(ab[1] * ac[2]) + std::abs(ab[2] * ac[1])) * std::abs(ad[0]) +
                           (std::abs(ab[2] * ac[0]) + std::abs(ab[0] * ac[2])) * std::abs(ad[1]) +
                           (std::abs(ab[0] * ac[1]) + std::abs(ab[1] * ac[0])) * std::abs(ad[2]);
  // (7 + 56 eps) eps bounds the error of this evaluation; 1e-15 > 7.8e-16.
  const double bound = 1e-15 * permanent;
  return det > bound ? 1 : (det < -bound ? -1 : 0);
}

/** Sign of Orient3D(a, b, c, d), exact. */
inline int
Orient3DSign(const double * a, const double * b, const double * c, const double * d)
{
  double ab[3], ac[3], ad[3];
  Subtract(b, a, ab);
  Subtract(c, a, ac);
  Subtract(d, a, ad);
  const int filtered = Orient3DFilteredSign(ab, ac, ad);
  if (filtered != 0)
  {
    return filtered;
  }
  const double m0 = ab[1] * ac[2] - ab[2] * ac[1];
  const double m1 = ab[2] * ac[0] - ab[0] * ac[2];
  const double m2 = ab[0] * ac[1] - ab[1] * ac[0];
  const double det = m0 * ad[0] + m1 * ad[1] + m2 * ad[2];
  if (!std::isfinite(det))
  {
    return det > 0.0 ? 1 : (det < 0.0 ? -1 : 0);
  }
  // Exact: the differences as two doubles each, then the 6 signed products
  // of the determinant's expansion, each a sum of 8 products of three doubles.
  double e[3][3][2];
  for (unsigned int k = 0; k < 3; ++k)
  {
    TwoDifference(b[k], a[k], e[0][k][0], e[0][k][1]);
    TwoDifference(c[k], a[k], e[1][k][0], e[1][k][1]);
    TwoDifference(d[k], a[k], e[2][k][0], e[2][k][1]);
  }
  ExactSum             sum;
  static constexpr int permutations[6][3] = { { 0, 1, 2 }, { 1, 2, 0 }, { 2, 0, 1 },
                                              { 0, 2, 1 }, { 2, 1, 0 }, { 1, 0, 2 } };
  for (unsigned int p = 0; p < 6; ++p)
  {
    const double sign = p < 3 ? 1.0 : -1.0;
    const int *  s = permutations[p];
    for (unsigned int i = 0; i < 2; ++i)
    {
      for (unsigned int j = 0; j < 2; ++j)
      {
        for (unsigned int k = 0; k < 2; ++k)
        {
          // det = sum over permutations of sign * ab[s0] ac[s1] ad[s2].
          sum.AddProduct(sign * e[0][s[0]][i], e[1][s[1]][j], e[2][s[2]][k]);
        }
      }
    }
  }
  return sum.Sign();
}

/** Sign of Orient2D(a, b, c, u, v), exact. */
inline int
Orient2DSign(const double * a, const double * b, const double * c, unsigned int u, unsigned int v)
{
  const double l = (b[u] - a[u]) * (c[v] - a[v]);
  const double r = (b[v] - a[v]) * (c[u] - a[u]);
  const double det = l - r;
  // (3 + 16 eps) eps bounds the error; 1e-15 > 3.4e-16.
  const double bound = 1e-15 * (std::abs(l) + std::abs(r));
  if (det > bound)
  {
    return 1;
  }
  if (det < -bound)
  {
    return -1;
  }
  if (!std::isfinite(det))
  {
    return det > 0.0 ? 1 : (det < 0.0 ? -1 : 0);
  }
  double bu[2], bv[2], cu[2], cv[2];
  TwoDifference(b[u], a[u], bu[0], bu[1]);
  TwoDifference(b[v], a[v], bv[0], bv[1]);
  TwoDifference(c[u], a[u], cu[0], cu[1]);
  TwoDifference(c[v], a[v], cv[0], cv[1]);
  ExactSum sum;
  for (unsigned int i = 0; i < 2; ++i)
  {
    for (unsigned int j = 0; j < 2; ++j)
    {
      sum.AddProduct(bu[i], cv[j], 1.0);
      sum.AddProduct(-bv[i], cu[j], 1.0);
    }
  }
  return sum.Sign();
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

/** Closed 2-D segments [p0, p1] and [q0, q1] (coordinates u, v) meet
 * (exact signs). */
inline bool
Segments2DIntersect(const double * p0,
                    const double * p1,
                    const double * q0,
                    const double * q1,
                    unsigned int   u,
                    unsigned int   v)
{
  const int o1 = Orient2DSign(p0, p1, q0, u, v);
  const int o2 = Orient2DSign(p0, p1, q1, u, v);
  const int o3 = Orient2DSign(q0, q1, p0, u, v);
  const int o4 = Orient2DSign(q0, q1, p1, u, v);
  if (o1 * o2 < 0 && o3 * o4 < 0)
  {
    return true;
  }
  // Collinear or touching: a point of one segment lies on the other.
  const auto onSegment = [u, v](const double * a, const double * b, const double * p) {
    return std::min(a[u], b[u]) <= p[u] && p[u] <= std::max(a[u], b[u]) && std::min(a[v], b[v]) <= p[v] &&
           p[v] <= std::max(a[v], b[v]);
  };
  return (o1 == 0 && onSegment(p0, p1, q0)) || (o2 == 0 && onSegment(p0, p1, q1)) ||
         (o3 == 0 && onSegment(q0, q1, p0)) || (o4 == 0 && onSegment(q0, q1, p1));
}

/** 2-D point p in the closed triangle (a, b, c) (exact signs). */
inline bool
PointInTriangle2D(const double * p,
                  const double * a,
                  const double * b,
                  const double * c,
                  unsigned int   u,
                  unsigned int   v)
{
  const int o1 = Orient2DSign(a, b, p, u, v);
  const int o2 = Orient2DSign(b, c, p, u, v);
  const int o3 = Orient2DSign(c, a, p, u, v);
  return (o1 >= 0 && o2 >= 0 && o3 >= 0) || (o1 <= 0 && o2 <= 0 && o3 <= 0);
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

/** The closed segment [p, q] meets the closed triangle b, given the exact
 * orientations s, t of p and q with respect to b's plane. */
inline bool
SegmentMeetsTriangle(const double * p, const double * q, const double * const * b, int s, int t, const double * normalB)
{
  if (s * t > 0)
  {
    return false;
  }
  if (s == 0 && t == 0)
  {
    return CoplanarSegmentTriangle(p, q, b, normalB);
  }
  // The segment reaches b's plane at one point: the line meets the closed
  // triangle when its three orientations with b's edges agree.
  const int o1 = Orient3DSign(p, q, b[0], b[1]);
  const int o2 = Orient3DSign(p, q, b[1], b[2]);
  const int o3 = Orient3DSign(p, q, b[2], b[0]);
  return (o1 >= 0 && o2 >= 0 && o3 >= 0) || (o1 <= 0 && o2 <= 0 && o3 <= 0);
}

/** The closed segment [p, q] meets the closed triangle b (exact signs). */
inline bool
SegmentMeetsTriangle(const double * p, const double * q, const double * const * b)
{
  double e1[3], e2[3], nb[3];
  Subtract(b[1], b[0], e1);
  Subtract(b[2], b[0], e2);
  Cross(e1, e2, nb);
  return SegmentMeetsTriangle(p, q, b, Orient3DSign(b[0], b[1], b[2], p), Orient3DSign(b[0], b[1], b[2], q), nb);
}

/** The edges of triangle a that meet the closed triangle b, given the
 * orientations sa[k] of a's vertices with respect to b's plane. */
inline bool
EdgesOfAMeetB(const double * const * a, const double * const * b, const int * sa, const double * normalB)
{
  for (unsigned int k = 0; k < 3; ++k)
  {
    const unsigned int l = (k + 1) % 3;
    if (SegmentMeetsTriangle(a[k], a[l], b, sa[k], sa[l], normalB))
    {
      return true;
    }
  }
  return false;
}

/** Whether the closed triangles a and b (arrays of 3 points) share a point:
 * crossing, touching or coplanar overlap. Exact: the decisions are signs of
 * orientation determinants (Orient3DSign(), Orient2DSign()) and comparisons
 * of coordinates, so that nearly coplanar triangles (the children of one
 * flat patch of a subdivided mesh, 1e-17 out of each other's planes) are
 * not called crossing by rounding. */
inline bool
TrianglesIntersect(const double * const * a, const double * const * b)
{
  int sb[3];
  int sa[3];
  for (unsigned int k = 0; k < 3; ++k)
  {
    sb[k] = Orient3DSign(a[0], a[1], a[2], b[k]);
  }
  if ((sb[0] > 0 && sb[1] > 0 && sb[2] > 0) || (sb[0] < 0 && sb[1] < 0 && sb[2] < 0))
  {
    return false;
  }
  for (unsigned int k = 0; k < 3; ++k)
  {
    sa[k] = Orient3DSign(b[0], b[1], b[2], a[k]);
  }
  if ((sa[0] > 0 && sa[1] > 0 && sa[2] > 0) || (sa[0] < 0 && sa[1] < 0 && sa[2] < 0))
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
  if (sb[0] == 0 && sb[1] == 0 && sb[2] == 0)
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

/** Distance between the closed segment [p, q] and the closed triangle b:
 * 0 when they meet (exact test), otherwise the smallest of the distances of
 * p and q to b and of the segment to b's edges. */
inline double
SegmentTriangleDistance(const double * p, const double * q, const double * const * b)
{
  if (SegmentMeetsTriangle(p, q, b))
  {
    return 0.0;
  }
  double d2 =
    std::min(PointTriangleDistanceSquared(p, b[0], b[1], b[2]), PointTriangleDistanceSquared(q, b[0], b[1], b[2]));
  for (unsigned int k = 0; k < 3; ++k)
  {
    d2 = std::min(d2, SegmentSegmentDistanceSquared(p, q, b[k], b[(k + 1) % 3]));
  }
  return std::sqrt(d2);
}

/** Gap of two triangles that share exactly one vertex, a[i] == b[j]: the
 * smaller of the distances between the edge of each opposite the shared
 * vertex and the other triangle. It is 0 exactly when the triangles meet
 * elsewhere than at the shared vertex: their intersection is convex and
 * holds the shared vertex v, and when it holds another point its farthest
 * point from v along that direction lies on one of these two edges. */
inline double
SharedVertexGap(const double * const * a, unsigned int i, const double * const * b, unsigned int j)
{
  const double ga = SegmentTriangleDistance(a[(i + 1) % 3], a[(i + 2) % 3], b);
  if (ga == 0.0)
  {
    return 0.0;
  }
  return std::min(ga, SegmentTriangleDistance(b[(j + 1) % 3], b[(j + 2) % 3], a));
}

/** The closed triangles a and b (3 points each) are at least d apart by a
 * separating axis: the line of their centroids or the normal of either;
 * false when none tells. A cheap test before TriangleDistance(): the pairs
 * that the collision index cannot clear by their motion are mostly still
 * apart along one of these axes. The projections are taken relative to
 * a[0], with a margin of 1e-12 of the coordinates' magnitude for their
 * rounding. */
inline bool
SeparatedBy(const double * const * a, const double * const * b, double d)
{
  double p[3][3], q[3][3];
  double scale = 0.0;
  for (unsigned int k = 0; k < 3; ++k)
  {
    Subtract(a[k], a[0], p[k]);
    Subtract(b[k], a[0], q[k]);
    for (unsigned int j = 0; j < 3; ++j)
    {
      scale = std::max({ scale, std::abs(p[k][j]), std::abs(q[k][j]) });
    }
  }
  double axes[3][3], e1[3], e2[3];
  for (unsigned int j = 0; j < 3; ++j)
  {
    axes[0][j] = (q[0][j] + q[1][j] + q[2][j]) - (p[0][j] + p[1][j] + p[2][j]);
  }
  Cross(p[1], p[2], axes[1]);
  Subtract(q[1], q[0], e1);
  Subtract(q[2], q[0], e2);
  Cross(e1, e2, axes[2]);
  for (const auto & axis : axes)
  {
    const double length = std::sqrt(Dot(axis, axis));
    if (!(length > 0.0))
    {
      continue;
    }
    const double pa[3] = { Dot(p[0], axis), Dot(p[1], axis), Dot(p[2], axis) };
    const double qb[3] = { Dot(q[0], axis), Dot(q[1], axis), Dot(q[2], axis) };
    const double separation = std::max(std::min({ qb[0], qb[1], qb[2] }) - std::max({ pa[0], pa[1], pa[2] }),
                                       std::min({ pa[0], pa[1], pa[2] }) - std::max({ qb[0], qb[1], qb[2] }));
    if (separation / length - 1e-12 * scale >= d)
    {
      return true;
    }
  }
  return false;
}

/** Writes to \a hits the indices j in [first, last) of the spheres whose
 * float centres (x, y, z: structure of arrays) lie closer to (px, py, pz)
 * than reach + r[j], and returns their number: a filter before an exact
 * test, so the caller widens \a reach by the floats' rounding. The arrays
 * must be readable 3 entries beyond \a last. SSE2 four spheres at a time
 * (about one in seven passes, so the indices are written without a
 * branch). */
inline SizeValueType
SpheresWithin(const float * x,
              const float * y,
              const float * z,
              const float * r,
              uint32_t      first,
              uint32_t      last,
              float         px,
              float         py,
              float         pz,
              float         reach,
              uint32_t *    hits)
{
  SizeValueType count = 0;
#if defined(__SSE2__)
  const __m128 vx = _mm_set1_ps(px);
  const __m128 vy = _mm_set1_ps(py);
  const __m128 vz = _mm_set1_ps(pz);
  const __m128 vr = _mm_set1_ps(reach);
  for (uint32_t j = first; j < last; j += 4)
  {
    const __m128 dx = _mm_sub_ps(_mm_loadu_ps(x + j), vx);
    const __m128 dy = _mm_sub_ps(_mm_loadu_ps(y + j), vy);
    const __m128 dz = _mm_sub_ps(_mm_loadu_ps(z + j), vz);
    const __m128 sum = _mm_add_ps(_mm_add_ps(_mm_mul_ps(dx, dx), _mm_mul_ps(dy, dy)), _mm_mul_ps(dz, dz));
    const __m128 limit = _mm_add_ps(_mm_loadu_ps(r + j), vr);
    unsigned int mask = static_cast<unsigned int>(_mm_movemask_ps(_mm_cmplt_ps(sum, _mm_mul_ps(limit, limit))));
    if (last - j < 4)
    {
      mask &= (1u << (last - j)) - 1u;
    }
    for (unsigned int b = 0; b < 4; ++b)
    {
      hits[count] = j + b;
      count += (mask >> b) & 1u;
    }
  }
#else
  for (uint32_t j = first; j < last; ++j)
  {
    const float dx = x[j] - px;
    const float dy = y[j] - py;
    const float dz = z[j] - pz;
    const float limit = r[j] + reach;
    hits[count] = j;
    count += dx * dx + dy * dy + dz * dz < limit * limit ? 1 : 0;
  }
#endif
  return count;
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
    m_EntryBoxes.resize(6 * m_Entries.size());
    for (SizeValueType e = 0; e < m_Entries.size(); ++e)
    {
      std::copy(boxes + 6 * m_Entries[e], boxes + 6 * m_Entries[e] + 6, m_EntryBoxes.data() + 6 * e);
    }
  }

  /** Calls f(u) for every box u != t that overlaps box t, once each. */
  template <typename TFunction>
  void
  ForEachOverlap(SizeValueType t, TFunction && f) const
  {
    this->ForEachOverlapOfBox(m_Boxes + 6 * t, t, f);
  }

  /** Calls f(u) for every box u != skip that overlaps the box \a query
   * (lower x, y, z, upper x, y, z; any box, also one reaching below the
   * grid's origin), once each. */
  template <typename TFunction>
  void
  ForEachOverlapOfBox(const float * query, SizeValueType skip, TFunction && f) const
  {
    if (m_Entries.empty())
    {
      return;
    }
    float a[6];
    for (unsigned int k = 0; k < 3; ++k)
    {
      a[k] = std::max(query[k], static_cast<float>(m_Origin[k]));
      a[3 + k] = query[3 + k];
      if (!(a[k] <= a[3 + k]))
      {
        return; // entirely below the origin: no box there
      }
    }
    int64_t lo[3], hi[3];
    this->CellRange(a, lo, hi);
    const SizeValueType t = skip;
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

  SizeValueType
  GetNumberOfBuckets() const
  {
    return m_BucketOffsets.empty() ? 0 : m_BucketOffsets.size() - 1;
  }

  /** Calls f(t, u), t < u, for every pair of overlapping boxes whose
   * intersection's lower corner lies in a cell of the buckets [begin, end):
   * over all buckets, every overlapping pair once. The pairs of one bucket
   * are enumerated from its entries, with the boxes copied in bucket order
   * (read in sequence). */
  template <typename TFunction>
  void
  ForEachPair(SizeValueType begin, SizeValueType end, TFunction && f) const
  {
    for (SizeValueType bucket = begin; bucket < end; ++bucket)
    {
      const SizeValueType first = m_BucketOffsets[bucket];
      const SizeValueType last = m_BucketOffsets[bucket + 1];
      for (SizeValueType i = first; i + 1 < last; ++i)
      {
        const float * a = m_EntryBoxes.data() + 6 * i;
        for (SizeValueType j = i + 1; j < last; ++j)
        {
          const float * b = m_EntryBoxes.data() + 6 * j;
          if (a[0] > b[3] || b[0] > a[3] || a[1] > b[4] || b[1] > a[4] || a[2] > b[5] || b[2] > a[5])
          {
            continue;
          }
          // The cell of the lower corner of the boxes' intersection: the
          // pair belongs to this bucket when that cell hashes to it.
          if (this->Bucket(this->CellOf(std::max(a[0], b[0]), 0),
                           this->CellOf(std::max(a[1], b[1]), 1),
                           this->CellOf(std::max(a[2], b[2]), 2)) != bucket)
          {
            continue;
          }
          const SizeValueType t = m_Entries[i];
          const SizeValueType u = m_Entries[j];
          if (t < u)
          {
            f(t, u);
          }
          else
          {
            f(u, t);
          }
        }
      }
    }
  }

  void
  Clear()
  {
    std::vector<SizeValueType>().swap(m_BucketOffsets);
    std::vector<uint32_t>().swap(m_Entries);
    std::vector<float>().swap(m_EntryBoxes);
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
  std::vector<float>         m_EntryBoxes; // the boxes of m_Entries, in its order
};

/** The float next below f (std::nextafter toward -infinity, inline: the
 * library call was 5 % of a step of the index). */
inline float
NextFloatDown(float f)
{
  if (!(f == f) || f == -std::numeric_limits<float>::infinity())
  {
    return f;
  }
  if (f == 0.0f)
  {
    return -std::numeric_limits<float>::denorm_min();
  }
  uint32_t bits;
  std::memcpy(&bits, &f, sizeof(bits));
  bits = f > 0.0f ? bits - 1 : bits + 1;
  std::memcpy(&f, &bits, sizeof(bits));
  return f;
}

/** The float next above f (std::nextafter toward +infinity). */
inline float
NextFloatUp(float f)
{
  return -NextFloatDown(-f);
}

/** A float not above m and one not below it, without a branch (the
 * per-point rounding of a step of the index; RoundDown() and RoundUp() are
 * tighter by up to two units in the last place and branch on every value).
 * m is clamped to the finite floats first; the nearest float f of m is
 * within half a unit in the last place of it, and |f| 2^-23 is at least one
 * unit, so f - |f| 2^-23 (rounded to nearest) is below m; 1e-30 covers
 * zero and the subnormals. m must not be NaN. */
inline void
OutwardFloats(double low, double high, float & below, float & above)
{
  constexpr double largest = std::numeric_limits<float>::max();
  const auto       lo = static_cast<float>(std::min(std::max(low, -largest), largest));
  const auto       hi = static_cast<float>(std::min(std::max(high, -largest), largest));
  below = lo - (std::abs(lo) * (1.0f / 8388608.0f) + 1e-30f);
  above = hi + (std::abs(hi) * (1.0f / 8388608.0f) + 1e-30f);
}

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
      flo = NextFloatDown(flo);
    }
    if (static_cast<double>(fhi) < hi)
    {
      fhi = NextFloatUp(fhi);
    }
    box[k] = flo;
    box[3 + k] = fhi;
  }
}
/** Runs body(begin, end) over [0, count) in blocks of 1024, on \a threader
 * (may be null: in this thread) over \a workUnits units. */
struct ParallelBlocks
{
  MultiThreaderBase * threader;
  unsigned int        workUnits;

  static constexpr SizeValueType Block = 1024;

  template <typename TBody>
  void
  operator()(SizeValueType count, TBody && body) const
  {
    constexpr SizeValueType block = Block;
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
  }
};
} // namespace SurfaceCollisionDetail

/** \class SurfaceCollision
 * \brief Keeps a moving triangulated surface from intersecting itself:
 * finds the pairs of triangles sharing no vertex that intersect or come
 * closer than a minimum distance, and reduces the displacements of their
 * vertices until every pair is clear.
 *
 * Works on flat arrays: point coordinates (3 doubles a point, physical
 * units) and triangles (3 point indices each). Pairs of triangles that share
 * an edge are not tested (they touch by construction). Pairs that share
 * exactly one vertex v (two triangles of one fan, "shared pairs") must not
 * fold into each other: their gap, the distance between the edge of each
 * opposite v and the other triangle (SharedVertexGap(), 0 exactly when they
 * meet elsewhere than at v), may not fall below the contact distance and
 * below its value at x; they are kept in a list of their own, built from
 * the connectivity, with their gaps at the reference (exact, at each
 * rebuild) in their triangles' clearances. The intersection predicates use
 * exact signs of the orientation determinants (Orient3DSign()), so that the
 * nearly coplanar triangles of a flat patch are not called crossing.
 *
 * Constrain() takes the current positions x (a state in which no pair
 * intersects) and the proposed next positions y, and modifies y. A pair
 * (A, B) violates the constraint at y when their distance is below the
 * minimum distance d and below their distance at x: a pair that was already
 * closer than d may stay so but not come closer, and from a state without
 * intersection (distance 0) none is created. The vertices of violating
 * pairs get their displacements halved, at the next violation halved again,
 * at the third set to zero; the pairs of every modified triangle are tested
 * again until none violates. This terminates (at worst every displacement
 * is zero, which gives back x) and the result is a state in which no pair
 * that did not intersect at x intersects, and no pair that was at least d
 * apart is closer than d.
 *
 * The index bounds the relative motion of nearby triangles, not their
 * absolute motion, so that a surface that moves fast as a whole (a balloon)
 * needs no more work than one at rest. At a rebuild, at reference positions
 * r (the proposed positions y of that step):
 * - a pyramid of cells: level 0 has cells of side s = R + 2 r99 (r99 the
 *   99th percentile of the triangles' radii, the largest distance from a
 *   triangle's centroid to its vertices), each triangle in the cell of its
 *   centroid, so that every candidate of a triangle of radius up to r99 is
 *   in one of the 27 cells around its own; level k has cells of side
 *   2^k s; the top level has at most two cells along each axis. The larger
 *   triangles (1 %, "large triangles") are in no cell;
 * - the candidate pairs: the pairs sharing no vertex closer than a radius
 *   R = d + 0.75 mean edge lengths (the pairs of triangles in neighbouring
 *   level-0 cells, and for the large triangles a uniform grid of the
 *   triangles' boxes widened by R/2), each with a lower bound of its
 *   distance at r (the larger of the bounding spheres' gap and the gap of
 *   the projections on the line of the centroids; the exact distance once a
 *   step needs it); every other pair is at least R apart at r. Each
 *   triangle's clearance is the smallest distance of its candidates, at most
 *   R, less d. At every step each large triangle t is tested against its
 *   candidates while the largest distance between its displacement box and
 *   the box of all displacements stays below R - d (no other pair can come
 *   within d), otherwise against the triangles whose boxes at r come within
 *   d plus that distance (the grid).
 * At each step the displacement y - r of every vertex is taken, and for
 * every triangle the box of its vertices' displacements; the box of a cell
 * is the union of its triangles', and its neighbourhood box the union over
 * the 27 cells around it. Two points of triangles t and u move apart or
 * together by at most the largest distance between a point of t's box and
 * one of u's (the points of a triangle are convex combinations of its
 * vertices). Hence, with the distance d(t, u) at r:
 * - a pair whose level-k cells are neighbours but whose level-(k-1) cells
 *   are not is at least 2^(k-1) s - r_t - r_u apart at r (r_t, r_u the
 *   triangles' radii): such pairs are clear when, for every level-k cell,
 *   the largest distance between its box and its neighbourhood box is below
 *   2^(k-1) s less the largest radius in the cell, less the largest in the
 *   27 cells around it, less d;
 * - a pair of neighbouring level-0 cells is clear when the largest distance
 *   rho_t between t's box and the neighbourhood box of its cell is below
 *   d(t, u) - d: below R - d for the pairs that are not candidates, below
 *   the clearance of t for all of them.
 * A triangle whose rho_t reaches R - d is deferred: besides its
 * candidates, it queries at that step a grid of the boxes at the reference
 * for every triangle within d plus its motion against the 27 cells around
 * its own. Level 1's test, when it fails for a cell, is redone per pair of
 * level-0 cells that are not neighbours but whose parents are (with their
 * own separation, radii and boxes: their centroids are at least h
 * sqrt(sum_k max(0, |D_k| - 1)^2) apart for coordinates differing by D_k),
 * and the triangles of the level-0 cells it does not clear are deferred
 * (their motion taken against the 27 level-1 cells around their parent).
 * Of the two sides of a pair that is not bounded only the one that moved
 * (the larger displacement box) is deferred. On a converging surface a few
 * triangles moving against the rest made most rebuilds. When a level
 * above 1 fails, or more than 1/64 of the triangles are deferred at one
 * step or 1/4 summed over the steps since the rebuild, or the deferred
 * triangles' grid queries have visited 4 boxes per triangle since the
 * rebuild (a surface in contact and moving everywhere), the index is
 * rebuilt at the proposed positions y (where every displacement is zero,
 * so that every bound holds); a pair that violates the constraint at y is
 * then closer than d at the reference, within its triangles' clearance,
 * and tested.
 * Only the triangles whose rho_t reaches their clearance ("tested
 * triangles") have their candidate pairs looked at, each first against the
 * pair's own bound (the largest distance between the two triangles' boxes
 * against d(t, u) - d) and then exactly (a separating axis, the line of the
 * centroids or a normal, first: SeparatedBy()). A surface moving as a whole, or
 * settled, costs a pass over the points, one over the triangles and one
 * over the cells per step. Once some displacements are reduced the modified
 * triangles are tested against every triangle whose box swept from x to y
 * (a uniform grid built for that step) comes within d of theirs: every
 * state that the reductions make lies in those boxes.
 *
 * A certificate without pairs, for a minimum distance of 0: when the
 * surface is closed (every edge in exactly two triangles, in opposite
 * directions) and, seen from the centroid c of its points at y, every
 * triangle has the same strict orientation and a generic ray from c crosses
 * exactly one triangle, the central projection from c onto a sphere is
 * one-to-one (IsStarShaped()): its degree is the number of crossings of any
 * ray that meets no edge, every point of the sphere is covered once, so no
 * two points of the surface coincide. No pair intersects and no fan folds,
 * and y is kept without the index (which the next step that needs it
 * rebuilds). One exact orientation sign per triangle, and three more for
 * the few triangles near the ray: a balloon inflating inside a convex or
 * star-shaped object costs a pass over the points and one over the
 * triangles per step. Only the contact distance (1e-6 of the mean edge) is
 * not measured: the index would hold two triangles that come closer than
 * that without touching, the certificate does not. After a step it does not
 * certify, it is tried again after 1, 2, 4, ... up to 64 steps, so that a
 * surface that is not star-shaped pays for it on at most one step in 64.
 * SetUseStarShapedCertificate(false) turns it off.
 *
 * A certificate carries to nearby positions: from the orientation
 * determinants and the points' distances to the centre comes a margin
 * (CarryCertificate(): a bound of how much the determinants can change
 * when the points of a triangle move by at most that much), and
 * positions with every point within the margin of the certified ones are
 * star-shaped from the same centre: a pass over the points instead of the
 * certificate's passes. When a few points (at most a 32nd) have left it,
 * the triangles around them are followed along the straight path from the
 * certified positions, by their own margins (the same bound for each
 * triangle alone) or else by 7 exact orientation signs each (CarriedTo()):
 * the certificate is computed again, with new margins, only when more
 * points have left, when one of those triangles may turn on the way, or
 * when the surface changes (SetSurface()). The margins are about a fifth
 * of the edge length on a regular sphere; a surface that settles moves
 * within them for many steps.
 * Where the margins do not last (a surface remeshed every few steps), the
 * margin is computed less often (CarryNow()).
 *
 * The certificate also takes a surface that is star-shaped but for a few
 * folds (IsStarShapedUpToFolds()), as a remeshing or a step leaves on a
 * surface of fine triangles: at most MaximumFoldTriangles triangles face
 * the other way from c, and the ray's crossings, counted with the signs of
 * their triangles' orientations, still sum to the orientation of the
 * others (the degree of the projection is 1). A direction from c that no
 * fold's projection covers is then covered by exactly one triangle, so two
 * triangles can only meet where both project next to a fold: the triangles
 * whose caps of directions meet a fold's cap (at most
 * MaximumFoldNeighbourhood) are tested pair by pair with the exact
 * predicates (TrianglesIntersect(), SharedVertexGap()). One more pass over
 * the triangles, and a few thousand pair tests, where the index would be
 * built (3 s for a million points).
 *
 * CountSelfIntersections() counts the intersecting pairs of a surface with
 * a grid of exact triangle boxes.
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

  /** For tuples of \a tupleSize keys (< numberOfKeys) stored one after the
   * other in \a keys, the tuples that hold each key, in compressed rows:
   * the tuples of key k are items[offsets[k]] to items[offsets[k + 1] - 1],
   * in increasing order (a tuple holding k twice is listed twice). */
  template <typename TOffset>
  static void
  GroupsOfKeys(const std::vector<IndexType> & keys,
               unsigned int                   tupleSize,
               SizeValueType                  numberOfKeys,
               std::vector<TOffset> &         offsets,
               std::vector<IndexType> &       items)
  {
    offsets.assign(numberOfKeys + 1, 0);
    for (const IndexType k : keys)
    {
      ++offsets[k + 1];
    }
    for (SizeValueType k = 0; k < numberOfKeys; ++k)
    {
      offsets[k + 1] += offsets[k];
    }
    items.resize(keys.size());
    std::vector<TOffset> next(offsets.begin(), offsets.end() - 1);
    for (SizeValueType i = 0; i < keys.size(); ++i)
    {
      items[next[keys[i]]++] = static_cast<IndexType>(i / tupleSize);
    }
  }

  /** Sets the surface's connectivity: \a numberOfTriangles triangles of 3
   * point indices (< numberOfPoints) each. Drops the spatial index; the next
   * Constrain() builds it. Call again whenever the mesh changes (remeshing,
   * renumbering). The tables of the pairs of triangles sharing one vertex
   * are made when the index first needs them: a surface accepted by the
   * star-shaped certificate at every step never needs them. \a knownClosed:
   * the caller knows that the triangles form a closed surface
   * (IsClosedSurface()'s condition), as DeformableMeshRemesher::
   * IsOutputClosed() tells of a remeshing's output, and the check (a pass
   * over the points, 60 % of this call on a sphere) is not made; a wrong
   * claim would let the certificate accept positions it must not. */
  void
  SetSurface(SizeValueType       numberOfPoints,
             const IndexType *   triangles,
             SizeValueType       numberOfTriangles,
             MultiThreaderBase * threader = nullptr,
             unsigned int        workUnits = 1,
             bool                knownClosed = false)
  {
    m_NumberOfPoints = numberOfPoints;
    m_Triangles.assign(triangles, triangles + 3 * numberOfTriangles);
    m_FanOffsets = nullptr;
    m_FanNeighbours = nullptr;
    // Per point, the triangles that use it: made when first needed (the
    // closed-surface check below, the constraint of a step the certificate
    // does not accept, the index's shared pairs).
    m_VertexTrianglesReady = false;
    // Whether a triangle repeats a point, and whether the surface is closed
    // (IsClosedSurface()): each directed edge (a, b) of a triangle is in no
    // other triangle of a's in that direction and in exactly one in the
    // other. Point by point: around point a, each triangle u of its fan is
    // (a, after, before) in its own order; the directed edge (a, b) of a
    // triangle is closed when b is the after of exactly one triangle of the
    // fan and the before of exactly one.
    const SurfaceCollisionDetail::ParallelBlocks parallel{ threader, workUnits };
    constexpr SizeValueType                      block = SurfaceCollisionDetail::ParallelBlocks::Block;
    std::vector<uint8_t>                         blockDegenerate((numberOfTriangles + block - 1) / block, 0);
    parallel(numberOfTriangles, [&](SizeValueType begin, SizeValueType end) {
      for (SizeValueType t = begin; t < end; ++t)
      {
        const IndexType * vt = m_Triangles.data() + 3 * t;
        if (vt[0] == vt[1] || vt[1] == vt[2] || vt[2] == vt[0])
        {
          blockDegenerate[begin / block] = 1;
          return;
        }
      }
    });
    m_RepeatedPoint = std::find(blockDegenerate.begin(), blockDegenerate.end(), 1) != blockDegenerate.end();
    bool closed = numberOfTriangles >= 4 && !m_RepeatedPoint;
    if (closed && !knownClosed)
    {
      this->EnsureVertexTriangles();
      std::vector<uint8_t> blockClosed((numberOfPoints + block - 1) / block, 1);
      parallel(numberOfPoints, [&](SizeValueType begin, SizeValueType end) {
        std::vector<IndexType> after;
        std::vector<IndexType> before;
        for (SizeValueType a = begin; a < end; ++a)
        {
          this->FanNeighbours(a, after, before);
          const SizeValueType n = after.size();
          for (SizeValueType i = 0; i < n; ++i)
          {
            unsigned int forward = 0;
            unsigned int backward = 0;
            for (SizeValueType j = 0; j < n; ++j)
            {
              forward += after[j] == after[i] ? 1 : 0;
              backward += before[j] == after[i] ? 1 : 0;
            }
            if (forward != 1 || backward != 1)
            {
              blockClosed[begin / block] = 0;
              return;
            }
          }
        }
      });
      closed = std::find(blockClosed.begin(), blockClosed.end(), 0) == blockClosed.end();
    }
    m_SharedPairsReady = false;
    m_SharedPairs.clear();
    m_SharedOffsets.clear();
    m_SharedOfTriangle.clear();
    m_SharedPartner.clear();
    m_SharedGaps.clear();
    m_SharedExact.clear();
    m_SharedComputed.clear();
    m_Closed = closed;
    m_CertificateWait = 0;
    m_CertificateBackoff = 0;
    // A carried certificate that the new surface ends (a remeshing), not
    // one that failed, does not make the next tries wait (CarryNow()): else
    // a carry tried a step before a remeshing, ended after one step, would
    // hold the carries back for 64 certificates.
    if (m_CarryTried && m_CarriedMargin > 0.0)
    {
      m_CarryYield = std::max<SizeValueType>(m_CarryYield, 2);
    }
    m_CarriedMargin = 0.0;
    m_HasSurface = true;
    this->Invalidate();
  }

  /** Whether Constrain() and FindContacts() may accept positions by the
   * star-shaped certificate (class documentation) when the minimum distance
   * is 0. On by default; off, every step goes through the index. */
  void
  SetUseStarShapedCertificate(bool use)
  {
    m_UseStarCertificate = use;
  }
  bool
  GetUseStarShapedCertificate() const
  {
    return m_UseStarCertificate;
  }

  /** Steps (and remeshings checked by FindContacts()) accepted by the
   * star-shaped certificate since SetSurface(). */
  SizeValueType
  GetNumberOfCertifiedSteps() const
  {
    return m_NumberOfCertifiedSteps;
  }

  /** True when SetSurface()'s triangles form a closed surface: every
   * directed edge (a, b) of a triangle is the edge (b, a) of exactly one
   * other triangle and of no other triangle in the same direction, and no
   * triangle repeats a point. */
  bool
  IsClosedSurface() const
  {
    return m_Closed;
  }

  /** The certificate (class documentation): true when the surface set by
   * SetSurface() is closed and, at the positions \a x (3 doubles a point),
   * every triangle seen from the centroid of the points has the same
   * strict orientation (exact signs) and a ray from the centroid crosses
   * exactly one triangle, none on its boundary. Then no two triangles
   * intersect and no two triangles of a fan fold into each other. False
   * when in doubt (a coordinate not finite, a zero sign, a ray through an
   * edge). It keeps per-point work buffers in this object (kept between
   * calls, so that a step allocates nothing): one call at a time per
   * object. */
  bool
  IsStarShaped(const double * x, MultiThreaderBase * threader = nullptr, unsigned int workUnits = 1) const
  {
    const SurfaceCollisionDetail::ParallelBlocks parallel{ threader, workUnits };
    return this->StarShaped(x, parallel);
  }

  /** The certificate that the collision test uses (class documentation):
   * IsStarShaped(), or star-shaped but for at most MaximumFoldTriangles
   * triangles facing the other way, whose neighbourhood (the triangles
   * whose projections from the centroid come near theirs, at most
   * MaximumFoldNeighbourhood) has no intersecting pair and no fan folded
   * into itself, tested pair by pair. True only when no two triangles
   * intersect; false when in doubt. One call at a time per object. */
  bool
  IsStarShapedUpToFolds(const double * x, MultiThreaderBase * threader = nullptr, unsigned int workUnits = 1) const
  {
    const SurfaceCollisionDetail::ParallelBlocks parallel{ threader, workUnits };
    return this->StarShapedUpToFolds(x, parallel);
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

  /** Each point's fan, as the caller's own tables hold it, for CarriedTo():
   * the neighbours of point i are \a neighbours[offsets[i]] to
   * \a neighbours[offsets[i + 1] - 1] in the cyclic order of its triangles,
   * (i, r_k, r_k+1) with k cyclic being a triangle of SetSurface() in its own
   * order (turned, not reversed). The certificate carried to new positions
   * then visits the triangles of the points beyond the carried margin
   * through these fans instead of a pass over all the triangles. Only for a
   * closed surface: every triangle is in the fans of its three points, so
   * offsets[NumberOfPoints] must be three times the number of triangles
   * (else the fans are ignored). The caller vouches that the fans describe
   * SetSurface()'s triangles exactly (a wrong claim would let the
   * certificate accept positions it must not), and keeps the arrays alive
   * and unchanged until SetPointFans(nullptr, nullptr) or SetSurface(),
   * which drops them. */
  void
  SetPointFans(const IndexType * offsets, const IndexType * neighbours)
  {
    const bool usable = offsets != nullptr && neighbours != nullptr && m_HasSurface && m_Closed && !m_RepeatedPoint &&
                        static_cast<SizeValueType>(offsets[m_NumberOfPoints]) == m_Triangles.size();
    m_FanOffsets = usable ? offsets : nullptr;
    m_FanNeighbours = usable ? neighbours : nullptr;
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

  /** Shared pairs whose bound the last rebuild computed (the others were
   * carried over from the rebuild before), for diagnostics and tests. */
  SizeValueType
  GetNumberOfComputedSharedGaps() const
  {
    return m_NumberOfComputedSharedGaps;
  }

  /** Number of index rebuilds since SetSurface(). */
  SizeValueType
  GetNumberOfRebuilds() const
  {
    return m_NumberOfRebuilds;
  }

  /** The same two counts since this object was made (across SetSurface()). */
  SizeValueType
  GetTotalNumberOfRebuilds() const
  {
    return m_TotalNumberOfRebuilds;
  }
  SizeValueType
  GetTotalNumberOfCertifiedSteps() const
  {
    return m_TotalNumberOfCertifiedSteps;
  }
  /** Of those, the steps certified by the margin carried from an earlier
   * certificate (CarryCertificate()), without the passes of the
   * certificate: a pass over the points. */
  SizeValueType
  GetTotalNumberOfCarriedCertificates() const
  {
    return m_TotalNumberOfCarriedCertificates;
  }
  /** How many times, in all, a triangle with a point beyond the carried
   * margin was found to keep its orientation by its own margin, without the
   * exact signs (CarriedTo()). */
  SizeValueType
  GetTotalNumberOfTrianglesWithinOwnMargin() const
  {
    return m_TotalNumberOfTrianglesWithinOwnMargin;
  }
  /** How many times, in all, a point beyond the carried margin was found
   * within its own (the least own margin of its triangles), so that its
   * triangles needed no test: with the fans of SetPointFans() only. */
  SizeValueType
  GetTotalNumberOfPointsWithinOwnMargin() const
  {
    return m_TotalNumberOfPointsWithinOwnMargin;
  }
  /** The margin carried from the last certificate without folds (0 when
   * none): positions with every point within it of the certified ones are
   * certified without the certificate's passes (CarryCertificate()). */
  double
  GetCarriedMargin() const
  {
    return m_CarriedMargin;
  }

  /** Triangles whose candidate pairs the last Constrain() looked at (their
   * relative motion reached their clearance). */
  SizeValueType
  GetNumberOfTestedTriangles() const
  {
    return m_NumberOfTestedTriangles;
  }

  /** Candidate pairs of the index (pairs closer than its radius at the
   * reference positions), for diagnostics. */
  SizeValueType
  GetNumberOfCandidatePairs() const
  {
    return m_Candidates.size() / 2;
  }

  /** Triangles of the index too large for its cells (above 1.25 times the
   * 99th percentile of the radii at the last rebuild), tested at every
   * step, for diagnostics. */
  SizeValueType
  GetNumberOfLargeTriangles() const
  {
    return m_Large.size();
  }

  /** The triangles deferred at the last Constrain() (their motion against
   * their neighbourhood reached what the index bounds, so they queried the
   * grid of the boxes at the reference instead of the index being
   * rebuilt), for diagnostics. */
  SizeValueType
  GetNumberOfDeferredTriangles() const
  {
    return m_NumberOfDeferredTriangles;
  }

  /** The points whose displacement the last Constrain() reduced. */
  const std::vector<IndexType> &
  GetConstrainedPoints() const
  {
    return m_ModifiedPoints;
  }

  /** The positions proposed for those points (3 doubles each, in the order
   * of GetConstrainedPoints()), as the last Constrain() received them. */
  const std::vector<double> &
  GetConstrainedProposals() const
  {
    return m_ModifiedProposals;
  }

  /** Distance below which two triangles count as touching whatever the
   * minimum distance: 1e-6 of the mean edge length (set at each rebuild). */
  double
  GetContactDistance() const
  {
    return m_ContactDistance;
  }

  /** Builds the index at the positions \a x (3 doubles a point, the
   * current positions of the next Constrain(), which keeps the index) and
   * finds the pairs in contact there: two triangles sharing no vertex closer
   * than \a minimumDistance or intersecting (closer than the contact
   * distance), and two triangles sharing one vertex whose gap
   * (SharedVertexGap()) is below the contact distance (folded into each
   * other). Only the pairs with at least one triangle flagged in \a changed
   * (a byte per triangle; null: every triangle) count: a change of the
   * surface (a remeshing) must not make contacts, those it did not touch may
   * stay. Sets to 1 the flag of both triangles of each pair found in
   * \a contacts (resized to the number of triangles) and returns the number
   * of pairs. The index's candidate pairs hold every pair closer than its
   * radius with a lower bound of its distance, so only pairs near contact
   * are measured exactly. 0 and no flag when a coordinate is not finite.
   * With \a tryCertificate false the star-shaped certificate is not tried
   * (CertifyContacts() was, and did not accept \a x). */
  SizeValueType
  FindContacts(const double *         x,
               const uint8_t *        changed,
               double                 minimumDistance,
               std::vector<uint8_t> & contacts,
               MultiThreaderBase *    threader,
               unsigned int           workUnits,
               bool                   tryCertificate = true)
  {
    const SizeValueType numberOfTriangles = this->GetNumberOfTriangles();
    contacts.assign(numberOfTriangles, 0);
    if (m_NumberOfPoints == 0 || numberOfTriangles < 2)
    {
      return 0;
    }
    if (m_Level.size() != m_NumberOfPoints)
    {
      m_Level.assign(m_NumberOfPoints, 0);
    }
    const SurfaceCollisionDetail::ParallelBlocks parallel{ threader, workUnits };
    if (tryCertificate && this->Certify(x, minimumDistance, parallel))
    {
      return 0;
    }
    this->EnsureSharedPairs(parallel);
    if (!this->Build(x, minimumDistance, parallel, false))
    {
      return 0;
    }
    const double                                              d = std::max(minimumDistance, m_ContactDistance);
    const double                                              c = m_ContactDistance;
    const SizeValueType                                       blocks = (numberOfTriangles + 1023) / 1024;
    std::vector<std::vector<std::pair<IndexType, IndexType>>> found(blocks);
    parallel(numberOfTriangles, [&](SizeValueType begin, SizeValueType end) {
      auto & out = found[begin / 1024];
      for (SizeValueType t = begin; t < end; ++t)
      {
        const bool        tChanged = changed == nullptr || changed[t] != 0;
        const IndexType * vt = m_Triangles.data() + 3 * t;
        const double *    a[3] = { x + 3 * vt[0], x + 3 * vt[1], x + 3 * vt[2] };
        // Each pair from its lower triangle (both rows list it).
        for (SizeValueType k = m_CandidateOffsets[t]; k < m_CandidateOffsets[t + 1]; ++k)
        {
          const IndexType u = m_Candidates[k];
          if (u < t || !(tChanged || changed[u] != 0) || static_cast<double>(m_CandidateGaps[k]) >= d)
          {
            continue;
          }
          const IndexType * vu = m_Triangles.data() + 3 * u;
          const double *    b[3] = { x + 3 * vu[0], x + 3 * vu[1], x + 3 * vu[2] };
          if (!SurfaceCollisionDetail::SeparatedBy(a, b, d) && SurfaceCollisionDetail::TriangleDistance(a, b) < d)
          {
            out.emplace_back(static_cast<IndexType>(t), u);
          }
        }
        for (IndexType k = m_SharedOffsets[t]; k < m_SharedOffsets[t + 1]; ++k)
        {
          const IndexType q = m_SharedOfTriangle[k];
          const IndexType u = m_SharedPartner[k];
          if (u < t || !(tChanged || changed[u] != 0) || static_cast<double>(m_SharedGaps[q]) >= c)
          {
            continue;
          }
          if (this->SharedGap(q, x) < c)
          {
            out.emplace_back(static_cast<IndexType>(t), u);
          }
        }
      }
    });
    SizeValueType count = 0;
    for (const auto & pairs : found)
    {
      for (const auto & pair : pairs)
      {
        contacts[pair.first] = 1;
        contacts[pair.second] = 1;
        ++count;
      }
    }
    return count;
  }

  /** FindContacts()'s first test alone: true when the star-shaped
   * certificate (class documentation) accepts the positions \a x at
   * \a minimumDistance, so that no pair is in contact (FindContacts() would
   * return 0), the certificate then kept as FindContacts() keeps it. For a
   * caller whose flags of changed triangles cost passes to make: it makes
   * them only when this returns false, then calls FindContacts() with
   * tryCertificate false. False also when the certificate does not apply
   * (an open surface, a minimum distance above 0, a wait after a failure). */
  bool
  CertifyContacts(const double * x, double minimumDistance, MultiThreaderBase * threader, unsigned int workUnits)
  {
    if (m_NumberOfPoints == 0 || this->GetNumberOfTriangles() < 2)
    {
      return false;
    }
    const SurfaceCollisionDetail::ParallelBlocks parallel{ threader, workUnits };
    return this->Certify(x, minimumDistance, parallel);
  }

  /** Modifies the proposed positions \a y (3 doubles a point) so that no
   * pair of triangles sharing no vertex violates the constraint described
   * in the class documentation, given the current positions \a x, clear.
   * \a minimumDistance is in the units of the coordinates, >= 0.
   * \a threader (may be null) runs the passes over \a workUnits units.
   * \a largestStep: the largest distance between a point of \a x and its
   * proposal in \a y, or a bound of it, when the caller knows it (a
   * deformable model's step does); it tells the certificate when a surface
   * has slowed down (CarryNow()). Negative: unknown. */
  Result
  Constrain(const double *      x,
            double *            y,
            double              minimumDistance,
            MultiThreaderBase * threader,
            unsigned int        workUnits,
            double              largestStep = -1.0)
  {
    Result              result;
    const SizeValueType n = m_NumberOfPoints;
    const SizeValueType numberOfTriangles = this->GetNumberOfTriangles();
    m_ModifiedPoints.clear();
    m_ModifiedProposals.clear();
    m_NumberOfTestedTriangles = 0;
    if (n == 0 || numberOfTriangles < 2)
    {
      return result;
    }
    if (m_Level.size() != n)
    {
      m_Level.assign(n, 0);
      m_IndexValid = false;
    }
    if (m_IndexValid && minimumDistance != m_MinimumDistance)
    {
      m_IndexValid = false;
    }
    const SurfaceCollisionDetail::ParallelBlocks parallel{ threader, workUnits };
    if (this->Certify(y, minimumDistance, parallel, largestStep))
    {
      m_NumberOfDeferredTriangles = 0;
      return result;
    }
    this->EnsureSharedPairs(parallel);

    // The bounds at y; when one fails the index is rebuilt at y (where
    // every displacement is zero and every bound holds).
    bool bounded = false;
    bool carry = false;
    if (m_IndexValid)
    {
      const BoundStatus status = this->Bound(y, parallel);
      if (status == BoundStatus::NonFinite)
      {
        return result; // a diverged step: the filter reports it
      }
      bounded = status == BoundStatus::Bounded;
      // Every triangle's box of y - r is set: the shared pairs' bounds at r
      // carry over to y.
      carry = true;
    }
    if (!bounded)
    {
      if (!this->Build(y, minimumDistance, parallel, carry))
      {
        return result; // a diverged step: the filter reports it
      }
      result.rebuilt = true;
      const BoundStatus status = this->Bound(y, parallel);
      if (status == BoundStatus::NonFinite)
      {
        return result;
      }
      bounded = status == BoundStatus::Bounded;
    }
    m_NumberOfDeferredTriangles = bounded ? m_Deferred.size() : 0;
    const double d = std::max(minimumDistance, m_ContactDistance);

    std::vector<std::pair<IndexType, IndexType>> violating;
    bool                                         sweptGridBuilt = false;
    const auto                                   buildSweptGrid = [&]() {
      if (!sweptGridBuilt)
      {
        this->BuildSweptGrid(x, y, d, parallel);
        sweptGridBuilt = true;
      }
    };
    if (bounded)
    {
      // The tested triangles' candidate pairs: the pairs of two tested
      // triangles from the one of lower index.
      const SizeValueType                                       blocks = (numberOfTriangles + 1023) / 1024;
      std::vector<std::vector<std::pair<IndexType, IndexType>>> found(blocks);
      std::vector<SizeValueType>                                tested(blocks, 0);
      parallel(numberOfTriangles, [&](SizeValueType begin, SizeValueType end) {
        auto &        out = found[begin / 1024];
        SizeValueType count = 0;
        for (SizeValueType t = begin; t < end; ++t)
        {
          if (!m_Active[t])
          {
            continue;
          }
          ++count;
          const float * bt = m_TriangleDelta.data() + 6 * t;
          for (SizeValueType c = m_CandidateOffsets[t]; c < m_CandidateOffsets[t + 1]; ++c)
          {
            const IndexType u = m_Candidates[c];
            if (m_Active[u] && u < t)
            {
              continue;
            }
            if (!this->CandidateMayViolate(t, c, LargestDistance(bt, m_TriangleDelta.data() + 6 * u), d))
            {
              continue;
            }
            if (this->Violates(t, u, x, y, d))
            {
              out.emplace_back(static_cast<IndexType>(std::min<SizeValueType>(t, u)),
                               static_cast<IndexType>(std::max<SizeValueType>(t, u)));
            }
          }
          for (IndexType k = m_SharedOffsets[t]; k < m_SharedOffsets[t + 1]; ++k)
          {
            const IndexType q = m_SharedOfTriangle[k];
            const IndexType u = m_SharedPartner[k];
            if (m_Active[u] && u < t)
            {
              continue;
            }
            if (this->SharedPairClear(q, LargestDistance(bt, m_TriangleDelta.data() + 6 * u)))
            {
              continue;
            }
            if (this->ViolatesShared(q, x, y, m_ContactDistance))
            {
              out.emplace_back(std::min<IndexType>(static_cast<IndexType>(t), u),
                               std::max<IndexType>(static_cast<IndexType>(t), u));
            }
          }
        }
        tested[begin / 1024] = count;
      });
      for (SizeValueType b = 0; b < blocks; ++b)
      {
        m_NumberOfTestedTriangles += tested[b];
        violating.insert(violating.end(), found[b].begin(), found[b].end());
      }
      // The large triangles (in no cell), at every step, against every
      // triangle that may have come within d: a pair closer than d at y is
      // closer than d + the largest distance between t's displacement box
      // and the box of all displacements at the reference.
      m_NumberOfTestedTriangles += m_Large.size();
      for (const IndexType t : m_Large)
      {
        if (!(LargestDistance(m_TriangleDelta.data() + 6 * t, m_GlobalDelta) < m_Radius - d))
        {
          this->EnsureReferenceGrid(); // before the parallel pass that queries it
          break;
        }
      }
      const SizeValueType                                       largeBlocks = (m_Large.size() + 1023) / 1024;
      std::vector<std::vector<std::pair<IndexType, IndexType>>> largeFound(largeBlocks);
      parallel(m_Large.size(), [&](SizeValueType begin, SizeValueType end) {
        auto &     out = largeFound[begin / 1024];
        const auto report = [&out](SizeValueType t, SizeValueType u) {
          out.emplace_back(static_cast<IndexType>(std::min(t, u)), static_cast<IndexType>(std::max(t, u)));
        };
        for (SizeValueType l = begin; l < end; ++l)
        {
          const IndexType t = m_Large[l];
          const float *   bt = m_TriangleDelta.data() + 6 * t;
          for (IndexType k = m_SharedOffsets[t]; k < m_SharedOffsets[t + 1]; ++k)
          {
            const IndexType q = m_SharedOfTriangle[k];
            const IndexType u = m_SharedPartner[k];
            if ((m_IsLarge[u] && u < t) ||
                this->SharedPairClear(q, LargestDistance(bt, m_TriangleDelta.data() + 6 * u)))
            {
              continue;
            }
            if (this->ViolatesShared(q, x, y, m_ContactDistance))
            {
              report(t, u);
            }
          }
          // A pair that is no candidate was at least R apart at the
          // reference, and moves by at most the largest distance between
          // t's displacement box and the box of all displacements: while
          // that stays below R - d only the candidates can come within d
          // (the grid query at every step was the large triangles' cost on
          // an uneven mesh).
          const double globalMotion = LargestDistance(bt, m_GlobalDelta);
          if (globalMotion < m_Radius - d)
          {
            for (SizeValueType c = m_CandidateOffsets[t]; c < m_CandidateOffsets[t + 1]; ++c)
            {
              const IndexType u = m_Candidates[c];
              if (m_IsLarge[u] && u < t)
              {
                continue;
              }
              if (this->CandidateMayViolate(t, c, LargestDistance(bt, m_TriangleDelta.data() + 6 * u), d) &&
                  this->Violates(t, u, x, y, d))
              {
                report(t, u);
              }
            }
            continue;
          }
          // Otherwise every triangle whose box at the reference comes
          // within d plus that motion.
          this->ForEachGridPartner(t, globalMotion, d, [&](SizeValueType u) {
            if (!(m_IsLarge[u] && u < t) && this->Violates(t, u, x, y, d))
            {
              report(t, u);
            }
          });
        }
      });
      for (const auto & block : largeFound)
      {
        violating.insert(violating.end(), block.begin(), block.end());
      }
      // The deferred triangles (Bound()): their candidates and shared pairs
      // are tested above when their rho reaches their clearance; their
      // other pairs that the levels do not bound were at least R apart at
      // the reference and move by at most the largest distance between t's
      // displacement box and the union of the cells around it
      // (DeferredMotion()), so every triangle whose box at the reference
      // comes within d plus that motion.
      m_NumberOfTestedTriangles += m_Deferred.size();
      if (!m_Deferred.empty())
      {
        this->EnsureReferenceGrid();
      }
      const SizeValueType                                       deferredBlocks = (m_Deferred.size() + 63) / 64;
      std::vector<std::vector<std::pair<IndexType, IndexType>>> deferredFound(deferredBlocks);
      std::vector<SizeValueType>                                deferredVisits(deferredBlocks, 0);
      const auto                                                deferredParallel = [&](auto && body) {
        if (deferredBlocks < 2 || threader == nullptr || workUnits < 2)
        {
          for (SizeValueType b = 0; b < deferredBlocks; ++b)
          {
            body(b);
          }
        }
        else
        {
          threader->SetNumberOfWorkUnits(workUnits);
          threader->ParallelizeArray(0, deferredBlocks, body, nullptr);
        }
      };
      deferredParallel([&](SizeValueType b) {
        auto & out = deferredFound[b];
        for (SizeValueType l = 64 * b; l < std::min<SizeValueType>(m_Deferred.size(), 64 * (b + 1)); ++l)
        {
          const IndexType t = m_Deferred[l];
          deferredVisits[b] += this->ForEachGridPartner(t, this->DeferredMotion(t), d, [&](SizeValueType u) {
            if (this->Violates(t, u, x, y, d))
            {
              out.emplace_back(static_cast<IndexType>(std::min<SizeValueType>(t, u)),
                               static_cast<IndexType>(std::max<SizeValueType>(t, u)));
            }
          });
        }
      });
      for (SizeValueType b = 0; b < deferredBlocks; ++b)
      {
        violating.insert(violating.end(), deferredFound[b].begin(), deferredFound[b].end());
        m_DeferredWork += deferredVisits[b];
      }
    }
    else
    {
      // No bound holds (a step that moves neighbouring triangles by more
      // than many edge lengths relative to each other): every pair whose
      // boxes swept from x to y come within d is tested.
      buildSweptGrid();
      m_NumberOfTestedTriangles = numberOfTriangles;
      for (SizeValueType t = 0; t < numberOfTriangles; ++t)
      {
        m_SweptGrid.ForEachOverlap(t, [&](SizeValueType u) {
          if (u < t || SurfaceCollisionDetail::ShareVertex(m_Triangles.data() + 3 * t, m_Triangles.data() + 3 * u))
          {
            return;
          }
          if (this->Violates(t, u, x, y, d))
          {
            violating.emplace_back(static_cast<IndexType>(t), static_cast<IndexType>(u));
          }
        });
      }
      for (SizeValueType q = 0; q < m_SharedGaps.size(); ++q)
      {
        if (this->ViolatesShared(q, x, y, m_ContactDistance))
        {
          violating.emplace_back(m_SharedPairs[2 * q], m_SharedPairs[2 * q + 1]);
        }
      }
    }

    // Reduce the displacements of the violating pairs' points, test the
    // pairs of the modified triangles again, until none violates.
    // When the index bounds every state between x and y (the displacement
    // boxes of x - r and y - r together), the modified triangles are tested
    // against their candidate and shared pairs (and, when there are large
    // triangles, the reference grid) instead of a grid of every triangle's
    // box swept from x to y.
    std::vector<IndexType> touched;
    std::vector<IndexType> triangles;
    bool                   sweptBounded = false;
    if (!violating.empty() && !sweptGridBuilt)
    {
      sweptBounded = this->Bound(y, parallel, x) == BoundStatus::Bounded;
    }
    if (!violating.empty())
    {
      this->EnsureVertexTriangles(); // the triangles of the points held back
    }
    while (!violating.empty())
    {
      if (!sweptBounded)
      {
        buildSweptGrid();
      }
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
          m_ModifiedProposals.insert(m_ModifiedProposals.end(), y + 3 * i, y + 3 * i + 3);
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
      // The grids the queries below need, built first: the tests then only
      // read, and run in parallel over blocks of triangles (their pairs
      // gathered in block order).
      if (sweptBounded && !(m_Large.empty() && m_Deferred.empty()))
      {
        bool needAll = false;
        bool needSpecial = false;
        for (const IndexType t : triangles)
        {
          if (!(LargestDistance(m_TriangleDelta.data() + 6 * t, m_GlobalDelta) < m_Radius - d))
          {
            (m_IsLarge[t] || m_IsDeferred[t] ? needAll : needSpecial) = true;
          }
        }
        if (needAll)
        {
          this->EnsureReferenceGrid();
        }
        if (needSpecial)
        {
          this->EnsureSpecialGrid();
        }
      }
      m_InRound.resize(numberOfTriangles, 0);
      for (const IndexType t : triangles)
      {
        m_InRound[t] = 1;
      }
      const SizeValueType                                       roundBlocks = (triangles.size() + 1023) / 1024;
      std::vector<std::vector<std::pair<IndexType, IndexType>>> roundFound(roundBlocks);
      parallel(triangles.size(), [&](SizeValueType begin, SizeValueType end) {
        auto & out = roundFound[begin / 1024];
        for (SizeValueType k = begin; k < end; ++k)
        {
          const IndexType t = triangles[k];
          const auto      test = [&](SizeValueType u) {
            if (this->Violates(t, u, x, y, d))
            {
              out.emplace_back(std::min<IndexType>(t, static_cast<IndexType>(u)),
                               std::max<IndexType>(t, static_cast<IndexType>(u)));
            }
          };
          if (sweptBounded)
          {
            // A candidate pair of two triangles of this round is tested
            // once, from the lower one (in a wide contact both sides of
            // most pairs are held back: each was tested twice).
            this->ForEachBoundedPartner(t, d, test, [this, t](IndexType u) { return u < t && m_InRound[u] != 0; });
          }
          else
          {
            m_SweptGrid.ForEachOverlap(t, [&](SizeValueType u) {
              if (!SurfaceCollisionDetail::ShareVertex(m_Triangles.data() + 3 * t, m_Triangles.data() + 3 * u))
              {
                test(u);
              }
            });
          }
          for (IndexType j = m_SharedOffsets[t]; j < m_SharedOffsets[t + 1]; ++j)
          {
            const IndexType q = m_SharedOfTriangle[j];
            if (this->ViolatesShared(q, x, y, m_ContactDistance))
            {
              out.emplace_back(m_SharedPairs[2 * q], m_SharedPairs[2 * q + 1]);
            }
          }
        }
      });
      for (const IndexType t : triangles)
      {
        m_InRound[t] = 0;
      }
      for (const auto & block : roundFound)
      {
        violating.insert(violating.end(), block.begin(), block.end());
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
   * \a x: 3 doubles a point; \a triangles: 3 point indices each. A closed
   * surface that the star-shaped certificate accepts (IsStarShaped()) has
   * none, and is not searched; otherwise a grid of the triangles' boxes is
   * searched, in parallel blocks when \a threader is given (the result does
   * not depend on it). */
  static SizeValueType
  CountSelfIntersections(const double *                            x,
                         const IndexType *                         triangles,
                         SizeValueType                             numberOfTriangles,
                         std::pair<SizeValueType, SizeValueType> * first = nullptr,
                         MultiThreaderBase *                       threader = nullptr,
                         unsigned int                              workUnits = 1)
  {
    const auto                                   none = std::numeric_limits<SizeValueType>::max();
    const SurfaceCollisionDetail::ParallelBlocks parallel{ threader, workUnits };
    if (first != nullptr)
    {
      *first = std::make_pair(none, none);
    }
    if (numberOfTriangles >= 4)
    {
      SizeValueType numberOfPoints = 0;
      for (SizeValueType i = 0; i < 3 * numberOfTriangles; ++i)
      {
        numberOfPoints = std::max<SizeValueType>(numberOfPoints, SizeValueType{ triangles[i] } + 1);
      }
      SurfaceCollision star;
      star.SetSurface(numberOfPoints, triangles, numberOfTriangles, threader, workUnits);
      if (star.StarShaped(x, parallel))
      {
        return 0;
      }
    }
    std::vector<float> boxes(6 * numberOfTriangles);
    parallel(numberOfTriangles, [&](SizeValueType begin, SizeValueType end) {
      for (SizeValueType t = begin; t < end; ++t)
      {
        double lo[3], hi[3];
        TriangleBox(x, triangles + 3 * t, lo, hi);
        SurfaceCollisionDetail::StoreBox(lo, hi, 0.0, boxes.data() + 6 * t);
      }
    });
    SurfaceCollisionDetail::BoxGrid grid;
    grid.Build(boxes.data(), numberOfTriangles);
    // Per block of triangles: the count and the first pair.
    using Pair = std::pair<SizeValueType, SizeValueType>;
    constexpr SizeValueType                     block = SurfaceCollisionDetail::ParallelBlocks::Block;
    std::vector<std::pair<SizeValueType, Pair>> blocks((numberOfTriangles + block - 1) / block,
                                                       std::make_pair(SizeValueType{ 0 }, Pair(none, none)));
    parallel(numberOfTriangles, [&](SizeValueType begin, SizeValueType end) {
      auto & result = blocks[begin / block];
      for (SizeValueType t = begin; t < end; ++t)
      {
        grid.ForEachOverlap(t, [&](SizeValueType u) {
          if (u < t || SurfaceCollisionDetail::ShareVertex(triangles + 3 * t, triangles + 3 * u))
          {
            return;
          }
          const double * a[3] = { x + 3 * triangles[3 * t],
                                  x + 3 * triangles[3 * t + 1],
                                  x + 3 * triangles[3 * t + 2] };
          const double * b[3] = { x + 3 * triangles[3 * u],
                                  x + 3 * triangles[3 * u + 1],
                                  x + 3 * triangles[3 * u + 2] };
          if (SurfaceCollisionDetail::TrianglesIntersect(a, b))
          {
            ++result.first;
            result.second = std::min(result.second, std::make_pair(t, u));
          }
        });
      }
    });
    SizeValueType count = 0;
    Pair          firstPair(none, none);
    for (const auto & result : blocks)
    {
      count += result.first;
      firstPair = std::min(firstPair, result.second);
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
   * fan-triangulated polygons), for quality reports; on the default
   * number of threads. */
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
    auto threader = MultiThreaderBase::New();
    return CountSelfIntersections(x.data(),
                                  triangles.data(),
                                  triangles.size() / 3,
                                  nullptr,
                                  threader,
                                  threader->GetMaximumNumberOfThreads() > 1 ? 4 * threader->GetMaximumNumberOfThreads()
                                                                            : 1);
  }

private:
  /** Radius of the candidate pairs at a rebuild, in mean edge lengths
   * (beyond the minimum distance). */
  static constexpr double RadiusFactor = 0.75;

  /** The shared pairs' bounds are computed up to this many R at a rebuild
   * (the separating axes tried until the bound reaches it), so that the
   * next rebuilds can carry them over (CarriedSharedGap()) while they stay
   * at least R. */
  static constexpr double SharedSlack = 1.25;

  /** A shared pair's bound is carried over while it has lost at most this
   * many R since it was computed. */
  static constexpr double SharedLoss = 0.25;

  /** Deferred triangles (Bound()) are tolerated up to 1/DeferredPerStep of
   * the triangles (at least 64) at one step and 1/DeferredPerRebuild (at
   * least 1024) summed over the steps since the rebuild; beyond, the index
   * is rebuilt (a deferred triangle's grid query costs about what a
   * rebuild costs per triangle). */
  static constexpr SizeValueType DeferredPerStep = 64;
  static constexpr SizeValueType DeferredPerRebuild = 4;
  /** ... and while their grid queries (and the halving loop's, while some
   * are deferred) have visited fewer than this many boxes per triangle
   * (at least 1024 triangles) since the rebuild. Where the deferred
   * triangles' motion is large each query visits many boxes: from the
   * sphere 0,-18,10,40 on ch2bet, whose 65 538-point level runs 500
   * iterations in contact, without this budget deferral cost 65 to 110 s
   * of that level; with 16 boxes 70 s; with 4 as without deferral. */
  static constexpr SizeValueType DeferredVisitsPerTriangle = 4;

  enum class BoundStatus
  {
    Bounded,
    Exceeded,
    NonFinite
  };

  /** One level of the pyramid of cells: the occupied cells (slots), sorted
   * by key, the slot of the next level each belongs to, the occupied cells
   * among the 27 around each (itself included), and per step the box of the
   * displacements in each cell and the union over its neighbours. */
  struct CellLevel
  {
    double                 cellSize{ 1.0 };
    std::vector<uint64_t>  keys;
    std::vector<IndexType> parents;
    std::vector<IndexType> childOffsets; // the finer level's cells in each cell (levels >= 1)
    std::vector<IndexType> children;
    std::vector<IndexType> neighbourOffsets;
    std::vector<IndexType> neighbours;
    std::vector<double>    radii;          // largest triangle radius in the cell
    std::vector<double>    neighbourRadii; // the same over the 27 cells around
    std::vector<float>     boxes;
    std::vector<float>     unions;
  };

  static constexpr unsigned int KeyBits = 21;

  static uint64_t
  Key(uint64_t i, uint64_t j, uint64_t k)
  {
    return (i << (2 * KeyBits)) | (j << KeyBits) | k;
  }

  /** Sorts \a pairs by their keys (below 2^keyBits), stably: a least
   * significant digit radix sort. */
  static void
  RadixSortByKey(std::vector<std::pair<uint64_t, IndexType>> & pairs, unsigned int keyBits)
  {
    constexpr unsigned int                      digitBits = 11;
    constexpr SizeValueType                     digits = SizeValueType{ 1 } << digitBits;
    std::vector<std::pair<uint64_t, IndexType>> other(pairs.size());
    std::vector<SizeValueType>                  counts(digits);
    for (unsigned int shift = 0; shift < keyBits; shift += digitBits)
    {
      std::fill(counts.begin(), counts.end(), 0);
      for (const auto & p : pairs)
      {
        ++counts[(p.first >> shift) & (digits - 1)];
      }
      SizeValueType sum = 0;
      for (auto & c : counts)
      {
        const SizeValueType here = c;
        c = sum;
        sum += here;
      }
      for (const auto & p : pairs)
      {
        other[counts[(p.first >> shift) & (digits - 1)]++] = p;
      }
      pairs.swap(other);
    }
  }

  /** The occupied cells among the 27 around each cell of \a level (itself
   * included), in increasing order, and the cells' boxes sized. The keys
   * are sorted and the three cells (dk = -1, 0, 1) of each of the 9
   * columns (di, dj) around a cell are consecutive keys, growing with the
   * cell's own: one cursor per column walks the keys once (27 binary
   * searches per cell were a twentieth of a rebuild). */
  static void
  FindNeighbours(CellLevel & level)
  {
    const SizeValueType cells = level.keys.size();
    const uint64_t      mask = (uint64_t{ 1 } << KeyBits) - 1;
    SizeValueType       cursors[9] = {};
    level.neighbourOffsets.assign(1, 0);
    level.neighbours.clear();
    for (SizeValueType s = 0; s < cells; ++s)
    {
      const uint64_t key = level.keys[s];
      const uint64_t ci = (key >> (2 * KeyBits)) & mask;
      const uint64_t cj = (key >> KeyBits) & mask;
      const uint64_t ck = key & mask;
      for (unsigned int column = 0; column < 9; ++column)
      {
        const int di = static_cast<int>(column / 3) - 1;
        const int dj = static_cast<int>(column % 3) - 1;
        // Level-0 coordinates start at 1; on coarser levels a coordinate 0
        // has no lower neighbour.
        if ((ci == 0 && di < 0) || (cj == 0 && dj < 0))
        {
          continue;
        }
        const uint64_t  first = Key(ci + di, cj + dj, ck == 0 ? 0 : ck - 1);
        const uint64_t  last = Key(ci + di, cj + dj, ck + 1);
        SizeValueType & cursor = cursors[column];
        while (cursor < cells && level.keys[cursor] < first)
        {
          ++cursor;
        }
        for (SizeValueType c = cursor; c < cells && level.keys[c] <= last; ++c)
        {
          level.neighbours.push_back(static_cast<IndexType>(c));
        }
      }
      level.neighbourOffsets.push_back(static_cast<IndexType>(level.neighbours.size()));
    }
    level.boxes.resize(6 * cells);
    level.unions.resize(6 * cells);
  }

  static void
  EmptyBox(float * box)
  {
    for (unsigned int k = 0; k < 3; ++k)
    {
      box[k] = std::numeric_limits<float>::infinity();
      box[3 + k] = -std::numeric_limits<float>::infinity();
    }
  }

  static void
  Unite(float * box, const float * other)
  {
    for (unsigned int k = 0; k < 3; ++k)
    {
      box[k] = std::min(box[k], other[k]);
      box[3 + k] = std::max(box[3 + k], other[3 + k]);
    }
  }

  /** The box of triangle v's vertex boxes (m_VertexDelta) in \a box. */
  void
  TriangleOfVertexBoxes(const IndexType * v, float * box) const
  {
    const float * a = m_VertexDelta.data() + 6 * v[0];
    const float * b = m_VertexDelta.data() + 6 * v[1];
    const float * c = m_VertexDelta.data() + 6 * v[2];
    for (unsigned int k = 0; k < 3; ++k)
    {
      box[k] = std::min(a[k], std::min(b[k], c[k]));
      box[3 + k] = std::max(a[3 + k], std::max(b[3 + k], c[3 + k]));
    }
  }

  /** Largest distance between a point of box a and a point of box b (boxes
   * as lower x, y, z, upper x, y, z), widened by a relative 1e-9 to bound
   * the rounding of the sum. */
  static double
  LargestDistance(const float * a, const float * b)
  {
    double sum = 0.0;
    for (unsigned int k = 0; k < 3; ++k)
    {
      const double e = std::max(static_cast<double>(a[3 + k]) - static_cast<double>(b[k]),
                                static_cast<double>(b[3 + k]) - static_cast<double>(a[k]));
      sum += e * e;
    }
    return std::sqrt(sum) * (1.0 + 1e-9);
  }

  static void
  TriangleBox(const double * x, const IndexType * v, double * lo, double * hi)
  {
    for (unsigned int k = 0; k < 3; ++k)
    {
      lo[k] = std::min({ x[3 * v[0] + k], x[3 * v[1] + k], x[3 * v[2] + k] });
      hi[k] = std::max({ x[3 * v[0] + k], x[3 * v[1] + k], x[3 * v[2] + k] });
    }
  }

  /** Number of vertices triangles t and u (3 indices each) share. */
  static unsigned int
  SharedVertices(const IndexType * t, const IndexType * u)
  {
    unsigned int count = 0;
    for (unsigned int i = 0; i < 3; ++i)
    {
      count += (t[i] == u[0]) + (t[i] == u[1]) + (t[i] == u[2]);
    }
    return count;
  }

  /** Calls f(u) for every triangle u sharing no vertex with t that may
   * come within d of it while the displacements since the reference stay in
   * the boxes of the last Bound() (which held): t's candidates whose pair
   * bound does not clear them and, when there are large triangles and t's
   * motion may reach R - d, the pairs of t with a large triangle found in
   * the reference grid. Other pairs are kept apart by the cells' bounds.
   * The candidates u for which skipCandidate(u) holds are left out (the
   * candidate lists are symmetric: the caller tests those pairs from u). */
  template <typename TFunction, typename TSkip>
  void
  ForEachBoundedPartner(SizeValueType t, double d, TFunction && f, TSkip && skipCandidate)
  {
    const float * bt = m_TriangleDelta.data() + 6 * t;
    for (SizeValueType c = m_CandidateOffsets[t]; c < m_CandidateOffsets[t + 1]; ++c)
    {
      const IndexType u = m_Candidates[c];
      if (skipCandidate(u) ||
          LargestDistance(bt, m_TriangleDelta.data() + 6 * u) < static_cast<double>(m_CandidateGaps[c]) - d)
      {
        continue;
      }
      f(u);
    }
    // The pairs with a large or deferred triangle that are no candidates
    // were at least R apart at the reference: clear while t's motion
    // against every displacement stays below R - d (the other pairs are
    // bounded by the triangles' rho).
    if (m_Large.empty() && m_Deferred.empty())
    {
      return;
    }
    const double globalMotion = LargestDistance(bt, m_GlobalDelta);
    if (globalMotion < m_Radius - d)
    {
      return;
    }
    // (The visits are not counted in the deferral budget: that budget
    // bounds the deferred triangles' own queries in the tested pass; the
    // halving loop's queries exhausted it at every step of a wide contact,
    // and every step rebuilt the index.)
    if (m_IsLarge[t] || m_IsDeferred[t])
    {
      this->EnsureReferenceGrid();
      this->ForEachGridPartner(t, globalMotion, d, f);
    }
    else
    {
      // Only the large and deferred triangles: the grid of their boxes
      // alone (a triangle that is neither queried the grid of every box,
      // and visited hundreds of boxes to find a few of them where a wide
      // contact held thousands of points at every step).
      this->EnsureSpecialGrid();
      this->ForEachGridPartner(t, globalMotion, d, f, m_SpecialGrid, m_SpecialTriangles.data());
    }
  }

  /** A bound of the motion of deferred triangle t against every triangle
   * of the cells whose pairs with t the levels of the pyramid do not bound
   * (Bound()): the union of the 27 level-0 cells around its own when only
   * its rho failed, of the 27 level-1 cells around its parent when level 1
   * did not clear its cell. */
  double
  DeferredMotion(SizeValueType t) const
  {
    const float *   bt = m_TriangleDelta.data() + 6 * t;
    const IndexType s = m_TriangleCell[t];
    if (m_Levels.size() > 1 && m_CellDeferred[s])
    {
      return LargestDistance(bt, m_Levels[1].unions.data() + 6 * m_Levels[0].parents[s]);
    }
    return LargestDistance(bt, m_Levels[0].unions.data() + 6 * s);
  }

  /** Calls f(u) for every triangle u sharing no vertex with t whose box at
   * the reference comes within d + \a motion of t's and that the
   * reference spheres and the pair's displacement boxes do not clear
   * (\a motion bounds t's displacement against every other; the grid must
   * be built, EnsureReferenceGrid()). */
  template <typename TFunction>
  SizeValueType
  ForEachGridPartner(SizeValueType t, double motion, double d, TFunction && f) const
  {
    return this->ForEachGridPartner(t, motion, d, f, m_ReferenceGrid, nullptr);
  }

  /** The same over \a grid, a grid of the reference boxes of the triangles
   * \a ids (null: of every triangle, entry u is triangle u). */
  template <typename TFunction>
  SizeValueType
  ForEachGridPartner(SizeValueType                           t,
                     double                                  motion,
                     double                                  d,
                     TFunction &&                            f,
                     const SurfaceCollisionDetail::BoxGrid & grid,
                     const IndexType *                       ids) const
  {
    SizeValueType visited = 0;
    const float * bt = m_TriangleDelta.data() + 6 * t;
    double        lo[3], hi[3];
    TriangleBox(m_Reference.data(), m_Triangles.data() + 3 * t, lo, hi);
    float query[6];
    SurfaceCollisionDetail::StoreBox(lo, hi, motion + d, query);
    const double * st = m_Spheres.data() + 4 * t;
    const auto     none = std::numeric_limits<SizeValueType>::max();
    grid.ForEachOverlapOfBox(query, ids == nullptr ? t : none, [&](SizeValueType entry) {
      const SizeValueType u = ids == nullptr ? entry : ids[entry];
      if (u == t)
      {
        return;
      }
      ++visited;
      if (SurfaceCollisionDetail::ShareVertex(m_Triangles.data() + 3 * t, m_Triangles.data() + 3 * u))
      {
        return;
      }
      const double * su = m_Spheres.data() + 4 * u;
      double         e[3];
      SurfaceCollisionDetail::Subtract(st, su, e);
      const double gap = std::sqrt(SurfaceCollisionDetail::Dot(e, e)) - st[3] - su[3];
      if (LargestDistance(bt, m_TriangleDelta.data() + 6 * u) < gap - d)
      {
        return;
      }
      f(u);
    });
    return visited;
  }

  /** Builds the grid of every triangle's box at the reference (widened by
   * R/2) if this index has not built it yet. */
  void
  EnsureReferenceGrid()
  {
    if (!m_ReferenceGridBuilt)
    {
      m_ReferenceGrid.Build(m_ReferenceBoxes.data(), this->GetNumberOfTriangles());
      m_ReferenceGridBuilt = true;
    }
  }

  /** Builds the grid of the reference boxes of the large and the deferred
   * triangles if this step has not built it yet (Bound() drops it). */
  void
  EnsureSpecialGrid()
  {
    if (m_SpecialGridBuilt)
    {
      return;
    }
    m_SpecialTriangles.assign(m_Large.begin(), m_Large.end());
    for (const IndexType t : m_Deferred)
    {
      if (!m_IsLarge[t])
      {
        m_SpecialTriangles.push_back(t);
      }
    }
    m_SpecialBoxes.resize(6 * m_SpecialTriangles.size());
    for (SizeValueType k = 0; k < m_SpecialTriangles.size(); ++k)
    {
      std::copy_n(m_ReferenceBoxes.data() + 6 * m_SpecialTriangles[k], 6, m_SpecialBoxes.data() + 6 * k);
    }
    m_SpecialGrid.Build(m_SpecialBoxes.data(), m_SpecialTriangles.size());
    m_SpecialGridBuilt = true;
  }

  /** Candidate c of triangle t may violate when the relative motion of the
   * pair is \a motion: the motion reaches the pair's gap at the reference
   * less d, the exact distance computed once per rebuild when the cheap
   * bound does not tell (each direction of a pair is an entry of its own
   * triangle's list: no two threads write one entry). */
  bool
  CandidateMayViolate(SizeValueType t, SizeValueType c, double motion, double d)
  {
    if (motion < static_cast<double>(m_CandidateGaps[c]) - d)
    {
      return false;
    }
    if (m_CandidateExact[c])
    {
      return true;
    }
    const IndexType * vt = m_Triangles.data() + 3 * t;
    const IndexType * vu = m_Triangles.data() + 3 * m_Candidates[c];
    const double *    r = m_Reference.data();
    const double *    a[3] = { r + 3 * vt[0], r + 3 * vt[1], r + 3 * vt[2] };
    const double *    b[3] = { r + 3 * vu[0], r + 3 * vu[1], r + 3 * vu[2] };
    m_CandidateGaps[c] = RoundDown(SurfaceCollisionDetail::TriangleDistance(a, b));
    m_CandidateExact[c] = 1;
    return !(motion < static_cast<double>(m_CandidateGaps[c]) - d);
  }

  /** The triangle of shared pair q other than t. */
  IndexType
  OtherOfShared(SizeValueType q, SizeValueType t) const
  {
    return m_SharedPairs[2 * q] == t ? m_SharedPairs[2 * q + 1] : m_SharedPairs[2 * q];
  }

  /** The vertex lists vt and vu of the two triangles of shared pair q, and
   * the corners i of vt and j of vu where they hold their shared vertex. */
  void
  SharedCorners(SizeValueType q, const IndexType *& vt, const IndexType *& vu, unsigned int & i, unsigned int & j) const
  {
    vt = m_Triangles.data() + 3 * m_SharedPairs[2 * q];
    vu = m_Triangles.data() + 3 * m_SharedPairs[2 * q + 1];
    i = 0;
    j = 0;
    for (unsigned int k = 0; k < 3; ++k)
    {
      for (unsigned int l = 0; l < 3; ++l)
      {
        if (vt[k] == vu[l])
        {
          i = k;
          j = l;
        }
      }
    }
  }

  /** SharedVertexGap() of the shared pair q at the positions x. */
  double
  SharedGap(SizeValueType q, const double * x) const
  {
    const IndexType * vt = nullptr;
    const IndexType * vu = nullptr;
    unsigned int      i = 0;
    unsigned int      j = 0;
    this->SharedCorners(q, vt, vu, i, j);
    const double * a[3] = { x + 3 * vt[0], x + 3 * vt[1], x + 3 * vt[2] };
    const double * b[3] = { x + 3 * vu[0], x + 3 * vu[1], x + 3 * vu[2] };
    return SurfaceCollisionDetail::SharedVertexGap(a, i, b, j);
  }

  /** A lower bound of SharedGap(q, x), cheap: the largest separation of
   * the far edge of one triangle and the other triangle along a few axes
   * (the line between the far edges' midpoints, the triangles' normals), the
   * smaller of the two. Once both separations reach \a enough the other
   * axes are not tried: the bound is then at least \a enough. */
  double
  SharedGapLowerBound(SizeValueType q, const double * x, double enough = std::numeric_limits<double>::infinity()) const
  {
    const IndexType * vt = nullptr;
    const IndexType * vu = nullptr;
    unsigned int      i = 0;
    unsigned int      j = 0;
    this->SharedCorners(q, vt, vu, i, j);
    using namespace SurfaceCollisionDetail;
    const double * v = x + 3 * vt[i];
    double         p[3], q1[3], r[3], s[3];
    Subtract(x + 3 * vt[(i + 1) % 3], v, p);
    Subtract(x + 3 * vt[(i + 2) % 3], v, q1);
    Subtract(x + 3 * vu[(j + 1) % 3], v, r);
    Subtract(x + 3 * vu[(j + 2) % 3], v, s);
    // Rounding of the differences and projections: a margin relative to the
    // coordinates' magnitude.
    const double scale = std::sqrt(std::max({ Dot(p, p), Dot(q1, q1), Dot(r, r), Dot(s, s) })) + std::abs(v[0]) +
                         std::abs(v[1]) + std::abs(v[2]);
    const double margin = 1e-12 * scale;
    const double target = enough + margin;
    const double target2 = target * target;
    // The separation of the far edge {e0, e1} of one triangle from the
    // other triangle {0, f0, f1} (coordinates relative to the shared vertex):
    // the largest along the other triangle's two edges' normals in its plane
    // at the shared vertex (pointing away from it), the line from its far
    // edge's midpoint to the far edge's midpoint and its normal; in squares
    // over the axes' squared lengths, one square root at the end (these
    // bounds are about a quarter of a rebuild).
    const auto bound = [target2](const double * e0, const double * e1, const double * f0, const double * f1) {
      double axes[4][3];
      Cross(f0, f1, axes[3]);
      Cross(f0, axes[3], axes[0]);
      Cross(axes[3], f1, axes[1]);
      for (unsigned int k = 0; k < 3; ++k)
      {
        axes[2][k] = (e0[k] + e1[k]) - (f0[k] + f1[k]);
      }
      double best = 0.0;
      for (const auto & axis : axes)
      {
        const double length2 = Dot(axis, axis);
        const double e[2] = { Dot(axis, e0), Dot(axis, e1) };
        const double f[2] = { Dot(axis, f0), Dot(axis, f1) };
        const double above = std::min(e[0], e[1]) - std::max({ 0.0, f[0], f[1] });
        const double below = std::min({ 0.0, f[0], f[1] }) - std::max(e[0], e[1]);
        const double separation = std::max(above, below);
        if (separation > 0.0 && length2 > 0.0)
        {
          best = std::max(best, separation * separation / length2);
          if (best >= target2)
          {
            break;
          }
        }
      }
      return std::sqrt(best);
    };
    const double first = bound(p, q1, r, s);
    const double second = first > margin ? bound(r, s, p, q1) : 0.0;
    return std::max(0.0, std::min(first, second) - margin);
  }

  /** The bound of shared pair q's gap at new reference positions r', from
   * its bound g at the reference r and every triangle's box of r' - r
   * (m_TriangleDelta): a point of one triangle and a point of the other
   * come closer by at most the largest distance between their boxes, so
   * the gap at r' is at least g less that distance (rounded down; 0 at
   * least). */
  float
  CarriedSharedGap(SizeValueType q) const
  {
    const double motion = LargestDistance(m_TriangleDelta.data() + 6 * m_SharedPairs[2 * q],
                                          m_TriangleDelta.data() + 6 * m_SharedPairs[2 * q + 1]);
    const double g = static_cast<double>(m_SharedGaps[q]) - motion;
    return g > 0.0 ? RoundDown(g * (1.0 - 1e-12)) : 0.0f;
  }

  /** Shared pair q cannot violate while the relative motion of its
   * triangles is below \a motion: its gap at the reference less the
   * contact distance is above the motion (with the exact gap computed once
   * per rebuild when the bound does not tell). */
  bool
  SharedPairClear(SizeValueType q, double motion)
  {
    if (motion < static_cast<double>(m_SharedGaps[q]) - m_ContactDistance)
    {
      return true;
    }
    if (m_SharedExact[q])
    {
      return false;
    }
    m_SharedGaps[q] = RoundDown(this->SharedGap(q, m_Reference.data()));
    m_SharedExact[q] = 1;
    return motion < static_cast<double>(m_SharedGaps[q]) - m_ContactDistance;
  }

  /** Shared pair q violates at y: its gap is below the contact distance c
   * and below its gap at x (the two triangles fold into each other). */
  bool
  ViolatesShared(SizeValueType q, const double * x, const double * y, double c) const
  {
    // The cheap separating-axis bound first: most pairs that a step's
    // motion does not clear are still far from folding.
    if (this->SharedGapLowerBound(q, y, c) >= c)
    {
      return false;
    }
    const double next = this->SharedGap(q, y);
    return next < c && next < this->SharedGap(q, x);
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
    if (SurfaceCollisionDetail::SeparatedBy(a, b, d))
    {
      return false;
    }
    const double next = SurfaceCollisionDetail::TriangleDistance(a, b);
    if (next >= d)
    {
      return false;
    }
    const double * a0[3] = { x + 3 * vt[0], x + 3 * vt[1], x + 3 * vt[2] };
    const double * b0[3] = { x + 3 * vu[0], x + 3 * vu[1], x + 3 * vu[2] };
    return next < SurfaceCollisionDetail::TriangleDistance(a0, b0);
  }

  /** Constrain()'s and FindContacts()'s use of the certificate: true when
   * the positions \a y are accepted without the index (which is then
   * dropped); after a failure the next tries wait 1, 2, 4, ... 64 calls.
   * \a largestStep: Constrain()'s, for CarryNow(); negative when unknown
   * (FindContacts()). */
  template <typename TParallel>
  bool
  Certify(const double * y, double minimumDistance, TParallel && parallel, double largestStep = -1.0)
  {
    if (!m_UseStarCertificate || !m_Closed || minimumDistance != 0.0)
    {
      return false;
    }
    if (m_CarriedMargin > 0.0 && this->CarriedTo(y, parallel))
    {
      ++m_NumberOfCertifiedSteps;
      ++m_TotalNumberOfCertifiedSteps;
      ++m_TotalNumberOfCarriedCertificates;
      ++m_CarryYield;
      m_IndexValid = false;
      return true;
    }
    if (m_CarriedMargin > 0.0 && m_CarryYield < 2 && largestStep >= 0.0)
    {
      // A carry that ended too soon: the step that ended it, against which
      // CarryNow() measures the later steps.
      m_FailedCarryStep = largestStep;
      m_ShortSteps = 0;
    }
    m_CarriedMargin = 0.0;
    if (m_CertificateWait > 0)
    {
      --m_CertificateWait;
      return false;
    }
    StarSummary pure;
    pure.undecided = true;
    // When a pure certificate would be carried, the carried margins are
    // computed in its pass over the triangles (CarryCertificate()).
    std::vector<double> & least = m_CarryLeast;
    least.clear();
    if (this->StarShapedUpToFolds(y, parallel, &pure, this->PlanCarry(largestStep).carry ? &least : nullptr))
    {
      m_CertificateBackoff = 0;
      ++m_NumberOfCertifiedSteps;
      ++m_TotalNumberOfCertifiedSteps;
      m_IndexValid = false;
      if (!pure.undecided && this->CarryNow(largestStep))
      {
        this->CarryCertificate(y, pure, least);
      }
      return true;
    }
    m_CertificateBackoff = std::min<unsigned int>(64, std::max<unsigned int>(1, 2 * m_CertificateBackoff));
    m_CertificateWait = m_CertificateBackoff;
    return false;
  }

  /** Whether to carry the certificate just computed. Carrying costs about
   * one and a half certificates (a pass over the triangles with three cross
   * products each, and a copy of the points): it pays when at least two
   * steps are carried. After a carried margin that certified fewer, the
   * next tries wait 1, 2, 4, ... 64 certificates (a surface remeshed every
   * few steps, whose margins do not last, or one that moves by more than
   * its margins at each step); after one that certified two or more, none.
   * While they wait, the steps are measured when the caller of Constrain()
   * gives their length (\a largestStep >= 0): two certified steps in a row
   * 8 times shorter than the one that ended the last carry end the wait,
   * once for that carry (a surface that travelled and has slowed down on
   * the object: on the benchmark's sphere of a million points, steps of
   * 0.4 to 0.48 mm against margins of 0.0002 to 0.013 mm while it
   * travelled, then 0.002 to 0.02 mm, and the wait of 64 certificates it
   * had reached kept three updates of 20 steps from carrying). */
  bool
  CarryNow(double largestStep)
  {
    const CarryPlan plan = this->PlanCarry(largestStep);
    m_CarryTried = plan.tried;
    m_CarryYield = plan.yield;
    m_CarryWait = plan.wait;
    m_CarryBackoff = plan.backoff;
    m_FailedCarryStep = plan.failedStep;
    m_ShortSteps = plan.shortSteps;
    return plan.carry;
  }

  /** CarryNow()'s decision and the state it leaves, without changing this
   * one (Certify() asks before the certificate whether a carry would
   * follow it). */
  struct CarryPlan
  {
    bool          carry;
    bool          tried;
    SizeValueType yield;
    unsigned int  wait;
    unsigned int  backoff;
    double        failedStep;
    unsigned int  shortSteps;
  };
  CarryPlan
  PlanCarry(double largestStep) const
  {
    CarryPlan plan{ false, m_CarryTried, m_CarryYield, m_CarryWait, m_CarryBackoff, m_FailedCarryStep, m_ShortSteps };
    if (plan.tried)
    {
      plan.backoff = plan.yield >= 2 ? 0 : std::min<unsigned int>(64, std::max<unsigned int>(1, 2 * plan.backoff));
      plan.wait = plan.backoff;
      plan.tried = false;
    }
    if (plan.wait > 0 && plan.failedStep > 0.0 && largestStep >= 0.0)
    {
      plan.shortSteps = 8.0 * largestStep <= plan.failedStep ? plan.shortSteps + 1 : 0;
      if (plan.shortSteps >= 2)
      {
        plan.wait = 0;
        plan.backoff = 0;
        plan.failedStep = 0.0;
        plan.shortSteps = 0;
      }
    }
    if (plan.wait > 0)
    {
      --plan.wait;
      return plan;
    }
    plan.carry = true;
    plan.tried = true;
    plan.yield = 0;
    return plan;
  }

  /** What StarShaped() found: the numbers of triangles of each strict
   * orientation seen from the centre, the ray's crossings of each, and
   * whether a sign was zero or the ray met an edge (then nothing else is
   * known). */
  struct StarSummary
  {
    SizeValueType positive{ 0 };
    SizeValueType negative{ 0 };
    SizeValueType positiveCrossings{ 0 };
    SizeValueType negativeCrossings{ 0 };
    bool          undecided{ true };
    double        centre[3]{ 0.0, 0.0, 0.0 };
    double        sharedBound{ 0.0 }; // StarOrientation()'s bound
  };

  /** For the triangle \a vt at positions \a x, seen from \a o: d = s D - r
   * (D its orientation determinant, s its certified \a sign, r the
   * determinants' \a rounding bound), and the squares of the upper bounds
   * of S1 and S2 that CarryCertificate() describes. */
  static void
  MarginTerms(const double *    x,
              const IndexType * vt,
              const double *    o,
              double            sign,
              double            rounding,
              double &          d,
              double &          s1Squared,
              double &          s2Squared)
  {
    using SurfaceCollisionDetail::Dot;
    double a[3];
    double b[3];
    double c[3];
    SurfaceCollisionDetail::Subtract(x + 3 * static_cast<SizeValueType>(vt[0]), o, a);
    SurfaceCollisionDetail::Subtract(x + 3 * static_cast<SizeValueType>(vt[1]), o, b);
    SurfaceCollisionDetail::Subtract(x + 3 * static_cast<SizeValueType>(vt[2]), o, c);
    double bc[3];
    double ca[3];
    double ab[3];
    SurfaceCollisionDetail::Cross(b, c, bc);
    SurfaceCollisionDetail::Cross(c, a, ca);
    SurfaceCollisionDetail::Cross(a, b, ab);
    d = sign * Dot(a, bc) - rounding;
    s1Squared = 3.0 * (Dot(bc, bc) + Dot(ca, ca) + Dot(ab, ab));
    s2Squared = 3.0 * (Dot(a, a) + Dot(b, b) + Dot(c, c));
  }

  /** The star-shaped certificate carried to nearby positions. With centre
   * o fixed, write A = a - o, B = b - o, C = c - o for a triangle's points
   * at the certified positions x0, whose orientation determinant
   * D = A . (B x C) has the sign s of all the others. Moving every point by
   * at most e changes D by at most e S1 + e^2 S2 + e^3, where
   * S1 = |B x C| + |C x A| + |A x B| and S2 = |A| + |B| + |C| (the
   * determinant is linear in each argument, and |det(u, v, w)| is at most
   * |u| |v| |w|). With d = s D - r (r: StarShaped()'s bound of the
   * rounding of D) and c = d / S1, which no root of that bound exceeds,
   * s D stays positive while every point of the triangle moves by at most
   * f = d / (S1 + c S2 + c^2) (then e S1 + e^2 S2 + e^3 <=
   * e (S1 + c S2 + c^2) <= d; S1 and S2 are taken from above by
   * (3 sum of squares)^1/2, which is S1 for three equal cross products, as
   * on a regular mesh far from the centre). The margin is the least f.
   * Positions y with every point within it of x0 are joined to x0 by the
   * straight path along which no triangle's orientation vanishes: the
   * surface never passes through o, the degree of the central projection
   * stays 1 and every triangle keeps its orientation, so y is star-shaped
   * from o as x0 is (class documentation). Computed after a certificate
   * that needed no fold, from the least f of each block of triangles that
   * the certificate's pass found (StarShaped() with \a least), with a copy
   * of x0. (That pass computes them when Certify() knows that a carry
   * would follow; a pass of their own, which read the triangles and their
   * points again, took 12 to 14 ms at a million points against the
   * certificate's 5 to 7, and the fused pass takes 14 to 16. A margin per
   * point, the least f of its triangles, carried 57 % of the combined
   * benchmark's steps at 100k against 53 %, for a pass over the corners
   * more.) */
  void
  CarryCertificate(const double * x, const StarSummary & summary, const std::vector<double> & least)
  {
    m_CarriedMargin = 0.0;
    constexpr SizeValueType block = SurfaceCollisionDetail::ParallelBlocks::Block;
    const SizeValueType     numberOfTriangles = this->GetNumberOfTriangles();
    if (numberOfTriangles == 0 || least.size() != (numberOfTriangles + block - 1) / block)
    {
      return;
    }
    const double   sign = summary.positive > 0 ? 1.0 : -1.0;
    const double * o = summary.centre;
    const double   rounding = summary.sharedBound;
    // Less a millionth: the rounding of S1, S2 and of the quotients.
    const double margin = (1.0 - 1e-6) * *std::min_element(least.begin(), least.end());
    if (!(margin > 0.0 && std::isfinite(margin)))
    {
      return;
    }
    m_CarriedFrom.assign(x, x + 3 * m_NumberOfPoints);
    m_CarriedMargin = margin;
    std::copy(o, o + 3, m_CarriedCentre);
    m_CarriedSign = sign > 0.0 ? 1 : -1;
    m_CarriedRounding = rounding;
    m_PointLimitsReady = false;
  }

  /** CarryCertificate()'s bound f of the triangle \a vt at \a x, seen from
   * \a o, taken into \a m, the least of a block's triangles so far. False
   * when f is not positive or not a number: \a m is then 0 (nothing is
   * carried) and the block's other triangles need not be seen. */
  static bool
  LowerCarriedMargin(const double * x, const IndexType * vt, const double * o, double sign, double rounding, double & m)
  {
    double d;
    double s1Squared;
    double s2Squared;
    MarginTerms(x, vt, o, sign, rounding, d, s1Squared, s2Squared);
    // The roots are left out when a bound from below of f is not below m:
    // (S1 + c S2 + c^2)^2 is at most 1.301 (S1^2 + c^2 S2^2 / 0.3 + 1000 c^4)
    // (Cauchy-Schwarz with the weights 1, 0.3 and 0.001, near the ratios of
    // the three terms far from the centre: c S2 / S1 was 0.28 to 0.29 and
    // c^2 / S1 about 1e-4 on the benchmark's sphere of a million points,
    // where this bound left 5 times fewer triangles to the roots than the
    // weights 1, 0.1 and 0.01).
    const double c2 = d * d / s1Squared;
    if (d > 0.0 && d * d >= m * m * (1.301 * (s1Squared + (1.0 / 0.3) * c2 * s2Squared + 1000.0 * c2 * c2)))
    {
      return true; // f >= m (false for a NaN: computed below)
    }
    const double s1 = std::sqrt(s1Squared);
    const double s2 = std::sqrt(s2Squared);
    const double positive = d > 0.0 ? d : 0.0; // NaN: 0
    const double cap = positive / s1;
    const double f = positive / (s1 + cap * s2 + cap * cap);
    m = f < m ? f : m;
    if (!(f > 0.0))
    {
      m = 0.0; // NaN or not positive: nothing carried
      return false;
    }
    return true;
  }

  /** Whether the triangle \a vt keeps its orientation seen from the carried
   * centre all along the straight path from the certified positions x0 to
   * \a y, by its own margin: CarryCertificate()'s bound f for this triangle
   * alone (the margin is the least f of all), computed again from x0 the
   * same way, and every point of the triangle within it of x0. */
  bool
  WithinOwnMargin(const double * x0, const double * y, const IndexType * vt) const
  {
    const double limit = this->OwnMarginLimit(x0, vt);
    if (!(limit > 0.0))
    {
      return false;
    }
    for (unsigned int k = 0; k < 3; ++k)
    {
      if (!(SquaredDistance(x0, y, vt[k]) <= limit)) // NaN: not within
      {
        return false;
      }
    }
    return true;
  }

  /** The square of the triangle \a vt's own margin (WithinOwnMargin()),
   * less the rounding of the squares, to compare with squared distances;
   * 0 when the triangle has none (its determinant not certainly of the
   * certified sign in this order, or NaN). Any turn of the triangle's
   * points gives a margin of its own (the same bound, rounded in another
   * order). */
  double
  OwnMarginLimit(const double * x0, const IndexType * vt) const
  {
    double d;
    double s1Squared;
    double s2Squared;
    MarginTerms(
      x0, vt, m_CarriedCentre, static_cast<double>(m_CarriedSign), m_CarriedRounding, d, s1Squared, s2Squared);
    if (!(d > 0.0))
    {
      return 0.0; // NaN too
    }
    const double s1 = std::sqrt(s1Squared);
    const double s2 = std::sqrt(s2Squared);
    const double cap = d / s1;
    // As the carried margin and its limit in CarriedTo(): a millionth less
    // for the rounding of S1, S2 and the quotients, another for the squares.
    const double f = (1.0 - 1e-6) * (d / (s1 + cap * s2 + cap * cap));
    const double limit = (1.0 - 1e-6) * f * f;
    return limit > 0.0 ? limit : 0.0;
  }

  /** The squared distance between point \a v at \a x0 and at \a y. */
  static double
  SquaredDistance(const double * x0, const double * y, IndexType v)
  {
    const double * p = x0 + 3 * static_cast<SizeValueType>(v);
    const double * q = y + 3 * static_cast<SizeValueType>(v);
    const double   dx = q[0] - p[0];
    const double   dy = q[1] - p[1];
    const double   dz = q[2] - p[2];
    return dx * dx + dy * dy + dz * dz;
  }

  /** Whether \a y is star-shaped from the centre of the carried certificate
   * (CarryCertificate()), decided without the certificate's passes: a pass
   * over the points finds those farther than the carried margin from their
   * certified positions x0. None: y is within the margin (CarryCertificate()).
   * At most a 32nd of the points: every triangle with such a point must keep
   * its orientation along the straight path from x0 to y. It does when its
   * points stay within its own margin (WithinOwnMargin(): the carried
   * margin is the least of these, and most triangles' are several times
   * larger); else, along the path, each
   * point is (1 - t) p0 + t p1, and the orientation determinant, linear in
   * each of the triangle's three points, is the sum, over the 8 ways of
   * taking each point at x0 or at y, of (1 - t)^i t^j (i points taken at
   * x0, j at y) times the determinant of that choice: a mean of the 8 with
   * non-negative weights. When the 7 that involve y have the sign of the
   * certified one (exact signs), the orientation never vanishes on the way.
   * The other triangles keep theirs by the margin, so along the whole path
   * no triangle passes through the centre: the degree of the central
   * projection stays 1 and y is star-shaped as x0 is (class documentation).
   * More points beyond the margin, a sign that differs, or a coordinate that
   * is not finite: false (the certificate is computed again). */
  template <typename TParallel>
  bool
  CarriedTo(const double * y, TParallel && parallel)
  {
    const SizeValueType n = m_NumberOfPoints;
    if (m_CarriedFrom.size() != 3 * n)
    {
      return false;
    }
    // Squared, with a millionth less for the rounding of the squares.
    const double               limit = (1.0 - 1e-6) * m_CarriedMargin * m_CarriedMargin;
    const double *             x0 = m_CarriedFrom.data();
    constexpr SizeValueType    block = SurfaceCollisionDetail::ParallelBlocks::Block;
    std::vector<SizeValueType> outside((n + block - 1) / block, 0);
    m_CarriedFar.resize(n);
    parallel(n, [&](SizeValueType begin, SizeValueType end) {
      SizeValueType count = 0;
      for (SizeValueType i = begin; i < end; ++i)
      {
        const double dx = y[3 * i] - x0[3 * i];
        const double dy = y[3 * i + 1] - x0[3 * i + 1];
        const double dz = y[3 * i + 2] - x0[3 * i + 2];
        const bool   far = !(dx * dx + dy * dy + dz * dz <= limit); // NaN: far
        m_CarriedFar[i] = far ? 1 : 0;
        count += far ? 1 : 0;
      }
      outside[begin / block] = count;
    });
    const SizeValueType far = std::accumulate(outside.begin(), outside.end(), SizeValueType{ 0 });
    if (far == 0)
    {
      return true;
    }
    if (far > n / 32)
    {
      return false;
    }
    if (m_FanOffsets != nullptr)
    {
      return this->CarriedAlongFans(x0, y, parallel);
    }
    const SizeValueType        numberOfTriangles = this->GetNumberOfTriangles();
    const uint8_t *            flags = m_CarriedFar.data();
    std::vector<uint8_t>       turned((numberOfTriangles + block - 1) / block, 0);
    std::vector<SizeValueType> ownMargins(turned.size(), 0);
    parallel(numberOfTriangles, [&](SizeValueType begin, SizeValueType end) {
      for (SizeValueType t = begin; t < end; ++t)
      {
        const IndexType * vt = m_Triangles.data() + 3 * t;
        if ((flags[vt[0]] | flags[vt[1]] | flags[vt[2]]) != 0 &&
            !this->KeepsCarriedOrientation(x0, y, vt, false, ownMargins[begin / block]))
        {
          turned[begin / block] = 1;
          return;
        }
      }
    });
    m_TotalNumberOfTrianglesWithinOwnMargin +=
      std::accumulate(ownMargins.begin(), ownMargins.end(), SizeValueType{ 0 });
    return std::find(turned.begin(), turned.end(), uint8_t{ 1 }) == turned.end();
  }

  /** CarriedTo()'s test of one triangle \a vt with a point beyond the
   * carried margin: whether it keeps its orientation along the straight
   * path from x0 to \a y, by its own margin (counted in \a ownMargins) or
   * else by the 7 exact signs that involve y. \a checkStart: the order of
   * \a vt is not known to be the certified one, whose sign at x0 is then
   * checked too (an 8th exact sign). */
  bool
  KeepsCarriedOrientation(const double *    x0,
                          const double *    y,
                          const IndexType * vt,
                          bool              checkStart,
                          SizeValueType &   ownMargins) const
  {
    if (this->WithinOwnMargin(x0, y, vt))
    {
      ++ownMargins;
      return true;
    }
    const double * ends[3][2];
    for (unsigned int k = 0; k < 3; ++k)
    {
      ends[k][0] = x0 + 3 * static_cast<SizeValueType>(vt[k]);
      ends[k][1] = y + 3 * static_cast<SizeValueType>(vt[k]);
    }
    for (unsigned int choice = checkStart ? 0 : 1; choice < 8; ++choice)
    {
      if (SurfaceCollisionDetail::Orient3DSign(
            m_CarriedCentre, ends[0][choice & 1], ends[1][(choice >> 1) & 1], ends[2][(choice >> 2) & 1]) !=
          m_CarriedSign)
      {
        return false;
      }
    }
    return true;
  }

  /** CarriedTo() with the caller's fans (SetPointFans()), in proportion
   * to the points beyond the carried margin (about 1 % of them at rest)
   * instead of the triangles. Each such point p has a margin of its own,
   * the least own margin of the triangles of its fan (OwnMarginLimit(), in
   * the fan's order: a turn of each triangle's own), computed once per
   * carried certificate when p first goes beyond the carried margin. A
   * point within it is cleared. A triangle whose points are each within a
   * margin of that triangle (the carried margin, or its own in the order of
   * one of its points) has every point within the largest of these, a
   * margin of the triangle: it keeps its orientation. So only the triangles
   * with a point not cleared are tested (KeepsCarriedOrientation()), each
   * once, from the first such point of the triangle. */
  template <typename TParallel>
  bool
  CarriedAlongFans(const double * x0, const double * y, TParallel && parallel)
  {
    const SizeValueType n = m_NumberOfPoints;
    uint8_t *           flags = m_CarriedFar.data();
    // Eight flags at a time: most words are 0.
    std::vector<IndexType> & farPoints = m_CarriedFarPoints;
    farPoints.clear();
    SizeValueType i = 0;
    for (; i + 8 <= n; i += 8)
    {
      uint64_t word;
      std::memcpy(&word, flags + i, sizeof(word));
      if (word == 0)
      {
        continue;
      }
      for (SizeValueType j = i; j < i + 8; ++j)
      {
        if (flags[j] != 0)
        {
          farPoints.push_back(static_cast<IndexType>(j));
        }
      }
    }
    for (; i < n; ++i)
    {
      if (flags[i] != 0)
      {
        farPoints.push_back(static_cast<IndexType>(i));
      }
    }
    if (!m_PointLimitsReady)
    {
      m_PointLimits.assign(n, -1.0);
      m_PointLimitsReady = true;
    }
    const SizeValueType     count = farPoints.size();
    constexpr SizeValueType block = SurfaceCollisionDetail::ParallelBlocks::Block;
    const IndexType *       offsets = m_FanOffsets;
    const IndexType *       neighbours = m_FanNeighbours;
    // The points' own margins: flag 2 for a point beyond its own.
    std::vector<SizeValueType> notCleared((count + block - 1) / block, 0);
    parallel(count, [&](SizeValueType begin, SizeValueType end) {
      for (SizeValueType k = begin; k < end; ++k)
      {
        const IndexType p = farPoints[k];
        double &        limit = m_PointLimits[p];
        if (limit < 0.0)
        {
          const SizeValueType first = offsets[p];
          const SizeValueType last = offsets[p + 1];
          double              least = std::numeric_limits<double>::infinity();
          for (SizeValueType j = first; j < last && least > 0.0; ++j)
          {
            const IndexType vt[3] = { p, neighbours[j], neighbours[j + 1 < last ? j + 1 : first] };
            least = std::min(least, this->OwnMarginLimit(x0, vt));
          }
          limit = least < std::numeric_limits<double>::infinity() ? least : 0.0;
        }
        if (!(limit > 0.0 && SquaredDistance(x0, y, p) <= limit)) // NaN: not cleared
        {
          flags[p] = 2;
          ++notCleared[begin / block];
        }
      }
    });
    const SizeValueType beyond = std::accumulate(notCleared.begin(), notCleared.end(), SizeValueType{ 0 });
    m_TotalNumberOfPointsWithinOwnMargin += count - beyond;
    if (beyond == 0)
    {
      return true;
    }
    std::vector<uint8_t>       turned((count + block - 1) / block, 0);
    std::vector<SizeValueType> ownMargins(turned.size(), 0);
    parallel(count, [&](SizeValueType begin, SizeValueType end) {
      for (SizeValueType k = begin; k < end; ++k)
      {
        const IndexType p = farPoints[k];
        if (flags[p] != 2)
        {
          continue;
        }
        const SizeValueType first = offsets[p];
        const SizeValueType last = offsets[p + 1];
        for (SizeValueType j = first; j < last; ++j)
        {
          const IndexType a = neighbours[j];
          const IndexType b = neighbours[j + 1 < last ? j + 1 : first];
          if ((flags[a] == 2 && a < p) || (flags[b] == 2 && b < p))
          {
            continue; // tested from its first point not cleared
          }
          const IndexType vt[3] = { p, a, b };
          if (!this->KeepsCarriedOrientation(x0, y, vt, true, ownMargins[begin / block]))
          {
            turned[begin / block] = 1;
            return;
          }
        }
      }
    });
    m_TotalNumberOfTrianglesWithinOwnMargin +=
      std::accumulate(ownMargins.begin(), ownMargins.end(), SizeValueType{ 0 });
    return std::find(turned.begin(), turned.end(), uint8_t{ 1 }) == turned.end();
  }

  /** IsStarShaped(), with the passes run by \a parallel; what it found in
   * \a summary when not null; in \a carryLeast when not null, the least
   * carried margin f of each block of triangles (LowerCarriedMargin(), for
   * CarryCertificate()). */
  template <typename TParallel>
  bool
  StarShaped(const double *        x,
             TParallel &&          parallel,
             StarSummary *         summary = nullptr,
             std::vector<double> * carryLeast = nullptr) const
  {
    const SizeValueType n = m_NumberOfPoints;
    const SizeValueType numberOfTriangles = this->GetNumberOfTriangles();
    if (!m_Closed || n == 0)
    {
      return false;
    }
    // The centroid, and the largest coordinate magnitude (the scale of the
    // rounding of the ray's screen below).
    constexpr SizeValueType            block = 1024;
    std::vector<std::array<double, 4>> partial((n + block - 1) / block);
    parallel(n, [&](SizeValueType begin, SizeValueType end) {
      std::array<double, 4> p{ { 0.0, 0.0, 0.0, 0.0 } };
      for (SizeValueType i = begin; i < end; ++i)
      {
        for (unsigned int k = 0; k < 3; ++k)
        {
          p[k] += x[3 * i + k];
          p[3] = std::max(p[3], std::abs(x[3 * i + k]));
        }
      }
      partial[begin / block] = p;
    });
    double sum[3] = { 0.0, 0.0, 0.0 };
    double scale = 0.0;
    for (const auto & p : partial)
    {
      sum[0] += p[0];
      sum[1] += p[1];
      sum[2] += p[2];
      scale = std::max(scale, p[3]);
    }
    const double centre[3] = { sum[0] / static_cast<double>(n),
                               sum[1] / static_cast<double>(n),
                               sum[2] / static_cast<double>(n) };
    if (!(std::isfinite(centre[0]) && std::isfinite(centre[1]) && std::isfinite(centre[2]) && std::isfinite(scale)))
    {
      return false;
    }
    // A ray in a direction of no symmetry of the usual meshes, and two unit
    // vectors orthogonal to it: a triangle whose three points lie strictly
    // on one side of the ray's line along either of them (with a margin far
    // above the rounding of these products) cannot meet the line.
    const double ray[3] = { 0.8017837257372732, 0.4454354031873740, 0.3984095364447979 };
    const double e1[3] = { -0.4856429311786321, 0.8741572761215377, 0.0 };
    const double e2[3] = { ray[1] * e1[2] - ray[2] * e1[1],
                           ray[2] * e1[0] - ray[0] * e1[2],
                           ray[0] * e1[1] - ray[1] * e1[0] };
    const double margin = 1e-9 * (scale + 1e-300);
    // A point on the ray as far out as the coordinates, so that its
    // rounding turns the ray by about 1e-16 at most.
    const double length = scale + 1.0;
    const double target[3] = { centre[0] + length * ray[0], centre[1] + length * ray[1], centre[2] + length * ray[2] };
    // Per point, once (a point is in about six triangles): its difference
    // from the centre, as Orient3DSign(centre, a, b, e) rounds it, and on
    // which side of the ray's line it lies, with the margin, along e1 (bit
    // 1: above, bit 2: below) and e2 (bits 4, 8). A triangle whose three
    // points share a bit lies strictly on one side and cannot meet the line.
    // And the largest magnitude of the differences, S: each of the six
    // products of the orientation determinant is at most S^3, which bounds
    // its rounding error for all triangles at once (the filter of
    // Orient3DFilteredSign() with 6 S^3 for the permanent).
    // The differences are not stored: the passes below form them again
    // from x (the same subtraction, so the same bits), which reads less
    // memory than an array of them written here and read back.
    m_StarSides.resize(n);
    std::vector<double> largest((n + block - 1) / block, 0.0);
    parallel(n, [&](SizeValueType begin, SizeValueType end) {
      double m = 0.0;
      for (SizeValueType i = begin; i < end; ++i)
      {
        double q[3];
        SurfaceCollisionDetail::Subtract(x + 3 * i, centre, q);
        const double p1 = q[0] * e1[0] + q[1] * e1[1] + q[2] * e1[2];
        const double p2 = q[0] * e2[0] + q[1] * e2[1] + q[2] * e2[2];
        m_StarSides[i] = static_cast<uint8_t>((p1 > margin ? 1 : 0) | (p1 < -margin ? 2 : 0) | (p2 > margin ? 4 : 0) |
                                              (p2 < -margin ? 8 : 0));
        m = std::max({ m, std::abs(q[0]), std::abs(q[1]), std::abs(q[2]) });
      }
      largest[begin / block] = m;
    });
    const double magnitude = *std::max_element(largest.begin(), largest.end());
    // 6 S^3 (1e-15 as in Orient3DFilteredSign()); infinite or not a number
    // when S^3 overflows: then every sign goes to the exact test.
    const double        sharedBound = 6e-15 * magnitude * magnitude * magnitude;
    const uint8_t *     sides = m_StarSides.data();
    const SizeValueType blocks = (numberOfTriangles + block - 1) / block;
    // Per block: positive and negative orientations, ray crossings (of
    // positive triangles, then of negative ones), and whether a sign was
    // zero.
    std::vector<std::array<SizeValueType, 5>> counts(blocks, std::array<SizeValueType, 5>{ { 0, 0, 0, 0, 0 } });
    // With \a carryLeast, each block's least carried margin f, each
    // triangle's with its own orientation: when the certificate is pure,
    // all have the one it is carried with.
    if (carryLeast != nullptr)
    {
      carryLeast->assign(blocks, 0.0);
    }
    parallel(numberOfTriangles, [&](SizeValueType begin, SizeValueType end) {
      auto & c = counts[begin / block];
      double least = std::numeric_limits<double>::infinity();
      bool   margins = carryLeast != nullptr;
      for (SizeValueType t = begin; t < end; ++t)
      {
        const IndexType * vt = m_Triangles.data() + 3 * t;
        const int         orientation = StarOrientation(x, vt, centre, sharedBound);
        if (orientation == 0)
        {
          ++c[3];
          continue;
        }
        if (margins)
        {
          margins = LowerCarriedMargin(x, vt, centre, static_cast<double>(orientation), sharedBound, least);
        }
        ++c[orientation > 0 ? 0 : 1];
        if ((sides[vt[0]] & sides[vt[1]] & sides[vt[2]]) != 0)
        {
          continue;
        }
        const double * a = x + 3 * vt[0];
        const double * b = x + 3 * vt[1];
        const double * e = x + 3 * vt[2];
        // The ray's direction in the cone of the triangle seen from the
        // centre: its three coordinates in the cone's edges (Cramer) have
        // the sign of the orientation.
        const int s1 = SurfaceCollisionDetail::Orient3DSign(centre, target, b, e);
        const int s2 = SurfaceCollisionDetail::Orient3DSign(centre, a, target, e);
        const int s3 = SurfaceCollisionDetail::Orient3DSign(centre, a, b, target);
        if (s1 == orientation && s2 == orientation && s3 == orientation)
        {
          ++c[orientation > 0 ? 2 : 4];
        }
        else if ((s1 == 0 || s1 == orientation) && (s2 == 0 || s2 == orientation) && (s3 == 0 || s3 == orientation))
        {
          ++c[3]; // the ray meets an edge or a point of the triangle
        }
      }
      if (carryLeast != nullptr)
      {
        (*carryLeast)[begin / block] = least;
      }
    });
    StarSummary found;
    std::copy(centre, centre + 3, found.centre);
    found.sharedBound = sharedBound;
    found.undecided = false;
    for (const auto & c : counts)
    {
      found.undecided = found.undecided || c[3] > 0;
      found.positive += c[0];
      found.negative += c[1];
      found.positiveCrossings += c[2];
      found.negativeCrossings += c[4];
    }
    if (summary != nullptr)
    {
      *summary = found;
    }
    return !found.undecided && (found.positive == 0 || found.negative == 0) &&
           found.positiveCrossings + found.negativeCrossings == 1;
  }

  /** The certificate of a surface star-shaped but for a few folds (class
   * documentation): StarShaped(), or, when it fails only because at most
   * MaximumFoldTriangles triangles face the other way from the centre and
   * the signed crossings of the ray sum to the orientation of the others
   * (the degree of the central projection is still 1), the exact test of
   * every pair of triangles whose projections from the centre come near
   * those of the folds (at most MaximumFoldNeighbourhood triangles): no two
   * sharing no point intersect (TrianglesIntersect()), no two sharing one
   * point fold into each other (SharedVertexGap() 0). Every other direction
   * from the centre is covered by exactly one triangle (positive minus
   * negative coverings is the degree, and no negative triangle covers it),
   * so no other pair can meet. False when in doubt. \a pure: StarShaped()'s
   * summary when it succeeded; \a carryLeast: as StarShaped()'s. */
  template <typename TParallel>
  bool
  StarShapedUpToFolds(const double *        x,
                      TParallel &&          parallel,
                      StarSummary *         pure = nullptr,
                      std::vector<double> * carryLeast = nullptr) const
  {
    using SurfaceCollisionDetail::Dot;
    StarSummary summary;
    if (this->StarShaped(x, parallel, &summary, carryLeast))
    {
      if (pure != nullptr)
      {
        *pure = summary;
      }
      return true;
    }
    const int           majority = summary.positive >= summary.negative ? 1 : -1;
    const SizeValueType minority = majority > 0 ? summary.negative : summary.positive;
    const auto          degree =
      static_cast<int64_t>(summary.positiveCrossings) - static_cast<int64_t>(summary.negativeCrossings);
    if (summary.undecided || minority == 0 || minority > MaximumFoldTriangles || degree != majority)
    {
      return false;
    }
    const SizeValueType     numberOfTriangles = this->GetNumberOfTriangles();
    const double *          centre = summary.centre;
    constexpr SizeValueType block = SurfaceCollisionDetail::ParallelBlocks::Block;
    const SizeValueType     blocks = (numberOfTriangles + block - 1) / block;
    // The cone of a triangle seen from the centre lies in the cap around
    // the unit sum of its corners' directions through the farthest corner
    // (a cap of less than a quarter sphere is convex on the sphere). Caps
    // of more than 84 degrees are taken as meeting everything.
    constexpr double widest = 0.1; // cosine of the widest cap measured
    // The unit direction of every point from the centre, once (each point
    // has six triangles: computed per triangle, they were three square roots
    // and nine divisions a triangle).
    const SizeValueType   numberOfPoints = m_NumberOfPoints;
    std::vector<double> & directions = m_FoldDirections;
    directions.resize(3 * numberOfPoints);
    parallel(numberOfPoints, [&](SizeValueType begin, SizeValueType end) {
      for (SizeValueType i = begin; i < end; ++i)
      {
        double q[3];
        SurfaceCollisionDetail::Subtract(x + 3 * i, centre, q);
        const double length = std::sqrt(Dot(q, q));
        for (unsigned int d = 0; d < 3; ++d)
        {
          directions[3 * i + d] = q[d] / length;
        }
      }
    });
    const double * unit = directions.data();
    const auto     cap = [unit](const IndexType * vt, double axis[3]) {
      const double * u[3] = { unit + 3 * static_cast<SizeValueType>(vt[0]),
                              unit + 3 * static_cast<SizeValueType>(vt[1]),
                              unit + 3 * static_cast<SizeValueType>(vt[2]) };
      for (unsigned int d = 0; d < 3; ++d)
      {
        axis[d] = u[0][d] + u[1][d] + u[2][d];
      }
      const double length = std::sqrt(Dot(axis, axis));
      if (!(length > 0.0))
      {
        return -1.0;
      }
      for (unsigned int d = 0; d < 3; ++d)
      {
        axis[d] /= length;
      }
      return std::min({ Dot(axis, u[0]), Dot(axis, u[1]), Dot(axis, u[2]) });
    };
    // The folds (the triangles of the minority orientation) and their caps,
    // widened by 1e-6 radians for the rounding of these products.
    std::vector<std::vector<IndexType>> parts(blocks);
    parallel(numberOfTriangles, [&](SizeValueType begin, SizeValueType end) {
      for (SizeValueType t = begin; t < end; ++t)
      {
        if (StarOrientation(x, m_Triangles.data() + 3 * t, centre, summary.sharedBound) == -majority)
        {
          parts[begin / block].push_back(static_cast<IndexType>(t));
        }
      }
    });
    std::vector<std::array<double, 5>> folds; // axis, cosine and sine of the radius
    for (const auto & part : parts)
    {
      for (const IndexType t : part)
      {
        std::array<double, 5> f;
        const double          cosine = cap(m_Triangles.data() + 3 * static_cast<SizeValueType>(t), f.data());
        if (!(cosine >= widest))
        {
          return false;
        }
        const double radius = std::acos(std::min(1.0, cosine)) + 1e-6;
        f[3] = std::cos(radius);
        f[4] = std::sin(radius);
        folds.push_back(f);
      }
    }
    // The triangles whose caps meet a fold's cap (the folds among them).
    parallel(numberOfTriangles, [&](SizeValueType begin, SizeValueType end) {
      auto & part = parts[begin / block];
      part.clear();
      for (SizeValueType t = begin; t < end; ++t)
      {
        double       axis[3];
        const double cosine = cap(m_Triangles.data() + 3 * t, axis);
        bool         near = !(cosine >= widest);
        if (!near)
        {
          const double sine = std::sqrt(std::max(0.0, 1.0 - cosine * cosine));
          for (const auto & f : folds)
          {
            // The angle between the axes at most the sum of the radii.
            if (Dot(axis, f.data()) >= cosine * f[3] - sine * f[4])
            {
              near = true;
              break;
            }
          }
        }
        if (near)
        {
          part.push_back(static_cast<IndexType>(t));
        }
      }
    });
    std::vector<IndexType> nearby;
    for (const auto & part : parts)
    {
      nearby.insert(nearby.end(), part.begin(), part.end());
      if (nearby.size() > MaximumFoldNeighbourhood)
      {
        return false;
      }
    }
    // Every pair of them, exactly (boxes first).
    const SizeValueType count = nearby.size();
    std::vector<double> boxes(6 * count);
    for (SizeValueType k = 0; k < count; ++k)
    {
      const IndexType * vt = m_Triangles.data() + 3 * static_cast<SizeValueType>(nearby[k]);
      for (unsigned int d = 0; d < 3; ++d)
      {
        boxes[6 * k + d] = std::min({ x[3 * vt[0] + d], x[3 * vt[1] + d], x[3 * vt[2] + d] });
        boxes[6 * k + 3 + d] = std::max({ x[3 * vt[0] + d], x[3 * vt[1] + d], x[3 * vt[2] + d] });
        if (!std::isfinite(boxes[6 * k + d]) || !std::isfinite(boxes[6 * k + 3 + d]))
        {
          return false; // the sweep's order needs numbers
        }
      }
    }
    // The pairs whose boxes overlap, by a sweep along x (all pairs of 4 096
    // triangles took about 12 ms); each pair tested in the order of nearby.
    std::vector<IndexType> byLow(count);
    std::iota(byLow.begin(), byLow.end(), IndexType{ 0 });
    std::sort(byLow.begin(), byLow.end(), [&boxes](IndexType k, IndexType l) {
      return boxes[6 * k] < boxes[6 * l] || (boxes[6 * k] == boxes[6 * l] && k < l);
    });
    for (SizeValueType s = 0; s < count; ++s)
    {
      for (SizeValueType r = s + 1; r < count && boxes[6 * byLow[r]] <= boxes[6 * byLow[s] + 3]; ++r)
      {
        const SizeValueType k = std::min(byLow[s], byLow[r]);
        const SizeValueType l = std::max(byLow[s], byLow[r]);
        const double *      bk = boxes.data() + 6 * k;
        const double *      bl = boxes.data() + 6 * l;
        if (bk[1] > bl[4] || bl[1] > bk[4] || bk[2] > bl[5] || bl[2] > bk[5])
        {
          continue;
        }
        const IndexType * vt = m_Triangles.data() + 3 * static_cast<SizeValueType>(nearby[k]);
        const double *    a[3] = { x + 3 * vt[0], x + 3 * vt[1], x + 3 * vt[2] };
        const IndexType * vu = m_Triangles.data() + 3 * static_cast<SizeValueType>(nearby[l]);
        const double *    b[3] = { x + 3 * vu[0], x + 3 * vu[1], x + 3 * vu[2] };
        unsigned int      shared = 0;
        unsigned int      i = 0;
        unsigned int      j = 0;
        for (unsigned int p = 0; p < 3; ++p)
        {
          for (unsigned int q = 0; q < 3; ++q)
          {
            if (vt[p] == vu[q])
            {
              ++shared;
              i = p;
              j = q;
            }
          }
        }
        if ((shared == 0 && SurfaceCollisionDetail::TrianglesIntersect(a, b)) ||
            (shared == 1 && SurfaceCollisionDetail::SharedVertexGap(a, i, b, j) == 0.0))
        {
          return false;
        }
      }
    }
    return true;
  }

  /** StarShapedUpToFolds()'s limits: the triangles facing the other way,
   * and the triangles near them whose pairs are tested. */
  static constexpr SizeValueType MaximumFoldTriangles = 256;
  static constexpr SizeValueType MaximumFoldNeighbourhood = 4096;

  /** The orientation of triangle \a vt seen from \a centre, from the
   * differences x - centre (rounded) and StarShaped()'s bound of their
   * rounding: 1, -1, or 0 when the centre lies in the triangle's plane
   * (exact sign). */
  static int
  StarOrientation(const double * x, const IndexType * vt, const double * centre, double sharedBound)
  {
    double q0[3];
    double q1[3];
    double q2[3];
    SurfaceCollisionDetail::Subtract(x + 3 * static_cast<SizeValueType>(vt[0]), centre, q0);
    SurfaceCollisionDetail::Subtract(x + 3 * static_cast<SizeValueType>(vt[1]), centre, q1);
    SurfaceCollisionDetail::Subtract(x + 3 * static_cast<SizeValueType>(vt[2]), centre, q2);
    const double m0 = q0[1] * q1[2] - q0[2] * q1[1];
    const double m1 = q0[2] * q1[0] - q0[0] * q1[2];
    const double m2 = q0[0] * q1[1] - q0[1] * q1[0];
    const double det = m0 * q2[0] + m1 * q2[1] + m2 * q2[2];
    int          orientation = det > sharedBound ? 1 : (det < -sharedBound ? -1 : 0);
    if (orientation == 0)
    {
      orientation = SurfaceCollisionDetail::Orient3DFilteredSign(q0, q1, q2);
    }
    if (orientation == 0)
    {
      orientation = SurfaceCollisionDetail::Orient3DSign(centre, x + 3 * vt[0], x + 3 * vt[1], x + 3 * vt[2]);
    }
    return orientation;
  }

  /** m as a float not above it. */
  static float
  RoundDown(double m)
  {
    const float f = static_cast<float>(m);
    return static_cast<double>(f) <= m ? f : SurfaceCollisionDetail::NextFloatDown(f);
  }

  /** Rebuilds the index at the reference positions x (see the class
   * documentation), with the candidate radius d + RadiusFactor mean edge
   * lengths. With \a carry, m_TriangleDelta holds every triangle's box of
   * x - r (r the former reference, Bound() at x): the shared pairs' bounds
   * are carried over (CarriedSharedGap()). False (and nothing built) when a
   * coordinate is not finite. */
  template <typename TParallel>
  bool
  Build(const double * x, double minimumDistance, TParallel && parallel, bool carry = false)
  {
    const SizeValueType n = m_NumberOfPoints;
    const SizeValueType numberOfTriangles = this->GetNumberOfTriangles();
    m_IndexValid = false;
    ++m_NumberOfRebuilds;
    ++m_TotalNumberOfRebuilds;
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
    if (!std::isfinite(meanEdge))
    {
      return false;
    }
    m_ContactDistance = 1e-6 * meanEdge;
    const double d = std::max(minimumDistance, m_ContactDistance);
    const double radius = d + RadiusFactor * std::max(meanEdge, m_ContactDistance);
    m_Radius = radius;
    m_Reference.assign(x, x + 3 * n);

    // Bounding spheres; the largest radius.
    m_Spheres.resize(4 * numberOfTriangles);
    parallel(numberOfTriangles, [&](SizeValueType begin, SizeValueType end) {
      for (SizeValueType t = begin; t < end; ++t)
      {
        Sphere(x, m_Triangles.data() + 3 * t, m_Spheres.data() + 4 * t);
      }
    });
    // The cells are sized for the triangles up to 1.25 times the 99th
    // percentile of the radii; the larger ("large triangles") are tested at
    // every step.
    double typicalRadius = 0.0;
    {
      std::vector<double> radii(numberOfTriangles);
      for (SizeValueType t = 0; t < numberOfTriangles; ++t)
      {
        radii[t] = m_Spheres[4 * t + 3];
      }
      const auto q = radii.begin() + static_cast<std::ptrdiff_t>((99 * (numberOfTriangles - 1)) / 100);
      std::nth_element(radii.begin(), q, radii.end());
      // The cells hold every triangle up to 1.25 times the 99th percentile
      // (on an even mesh, all of them: the large triangles' grid queries
      // at every step were a fifth of a step of the index).
      const double limit = 1.25 * *q;
      typicalRadius = *q;
      for (const double r : radii)
      {
        if (r <= limit)
        {
          typicalRadius = std::max(typicalRadius, r);
        }
      }
    }

    m_Large.clear();
    m_IsLarge.assign(numberOfTriangles, 0);
    for (SizeValueType t = 0; t < numberOfTriangles; ++t)
    {
      if (m_Spheres[4 * t + 3] > typicalRadius)
      {
        m_Large.push_back(static_cast<IndexType>(t));
        m_IsLarge[t] = 1;
      }
    }

    // The boxes at the reference widened by R/2: two triangles whose boxes
    // do not overlap are at least R apart.
    std::vector<float> & boxes = m_ReferenceBoxes;
    boxes.resize(6 * numberOfTriangles);
    parallel(numberOfTriangles, [&](SizeValueType begin, SizeValueType end) {
      for (SizeValueType t = begin; t < end; ++t)
      {
        double lo[3], hi[3];
        TriangleBox(x, m_Triangles.data() + 3 * t, lo, hi);
        SurfaceCollisionDetail::StoreBox(lo, hi, 0.5 * radius, boxes.data() + 6 * t);
      }
    });

    // Level 0 of the pyramid of cells: cells of side R + 2 r99 (larger when
    // the keys would not fit), each triangle in the cell of its centroid;
    // the large triangles are in no cell.
    double lower[3] = { std::numeric_limits<double>::infinity(),
                        std::numeric_limits<double>::infinity(),
                        std::numeric_limits<double>::infinity() };
    double upper[3] = { -std::numeric_limits<double>::infinity(),
                        -std::numeric_limits<double>::infinity(),
                        -std::numeric_limits<double>::infinity() };
    for (SizeValueType t = 0; t < numberOfTriangles; ++t)
    {
      for (unsigned int k = 0; k < 3; ++k)
      {
        lower[k] = std::min(lower[k], m_Spheres[4 * t + k]);
        upper[k] = std::max(upper[k], m_Spheres[4 * t + k]);
      }
    }
    double cellSize = (radius + 2.0 * typicalRadius) * (1.0 + 1e-9);
    for (unsigned int k = 0; k < 3; ++k)
    {
      cellSize = std::max(cellSize, (upper[k] - lower[k]) / static_cast<double>((uint64_t{ 1 } << KeyBits) - 4));
    }
    if (!(cellSize > 0.0) || !std::isfinite(cellSize))
    {
      cellSize = 1.0; // a degenerate surface (every point at one place)
    }
    // The triangles sorted by the key of their cell, then by index: a
    // radix sort of (key, triangle) pairs in triangle order on keys packed to
    // the bits the cell coordinates need (std::sort was a tenth of a rebuild).
    unsigned int bits[3];
    for (unsigned int k = 0; k < 3; ++k)
    {
      const auto largest = static_cast<uint64_t>((upper[k] - lower[k]) / cellSize) + 1;
      bits[k] = 1;
      while (bits[k] < KeyBits && (largest >> bits[k]) != 0)
      {
        ++bits[k];
      }
    }
    std::vector<std::pair<uint64_t, IndexType>> order;
    order.reserve(numberOfTriangles - m_Large.size());
    for (SizeValueType t = 0; t < numberOfTriangles; ++t)
    {
      if (m_IsLarge[t])
      {
        continue;
      }
      uint64_t c[3];
      for (unsigned int k = 0; k < 3; ++k)
      {
        c[k] = static_cast<uint64_t>((m_Spheres[4 * t + k] - lower[k]) / cellSize) + 1;
      }
      order.emplace_back((c[0] << (bits[1] + bits[2])) | (c[1] << bits[2]) | c[2], static_cast<IndexType>(t));
    }
    RadixSortByKey(order, bits[0] + bits[1] + bits[2]);
    for (auto & entry : order)
    {
      const uint64_t packed = entry.first;
      entry.first = Key(packed >> (bits[1] + bits[2]),
                        (packed >> bits[2]) & ((uint64_t{ 1 } << bits[1]) - 1),
                        packed & ((uint64_t{ 1 } << bits[2]) - 1));
    }
    m_Levels.clear();
    m_Levels.emplace_back();
    m_Levels[0].cellSize = cellSize;
    m_CellOrder.resize(order.size());
    m_CellOffsets.clear();
    m_TriangleCell.assign(numberOfTriangles, std::numeric_limits<IndexType>::max());
    for (SizeValueType i = 0; i < order.size(); ++i)
    {
      const IndexType t = order[i].second;
      m_CellOrder[i] = t;
      if (m_Levels[0].keys.empty() || m_Levels[0].keys.back() != order[i].first)
      {
        m_Levels[0].keys.push_back(order[i].first);
        m_CellOffsets.push_back(static_cast<IndexType>(i));
      }
      m_TriangleCell[t] = static_cast<IndexType>(m_Levels[0].keys.size() - 1);
    }
    m_CellOffsets.push_back(static_cast<IndexType>(m_CellOrder.size()));
    std::vector<std::pair<uint64_t, IndexType>>().swap(order);
    FindNeighbours(m_Levels[0]);

    // Candidate pairs, closer than R. Two triangles of level-0 cells are
    // within R of each other only when their centroids are within
    // R + 2 r99 <= the cell size: in neighbouring cells. So the pairs of
    // cells are enumerated over each cell and the neighbours after it, the
    // spheres copied in cell order (read in sequence). The large triangles,
    // in no cell, query a grid of the boxes (kept for their tests at every
    // step).
    struct Pair
    {
      IndexType t;
      IndexType u;
      float     gap;
    };
    // The triangles' spheres, vertices, corners and boxes copied in cell
    // order, so that the pairs of two cells read them in sequence.
    const SizeValueType celled = m_CellOrder.size();
    std::vector<double> cellSpheres(4 * celled);
    // The spheres again as floats, one array per coordinate (4 entries of
    // padding: SpheresWithin() reads up to 3 beyond a cell's end), for the
    // filter before the double test; the reach is widened by the floats'
    // rounding (relative 2^-24 on each coordinate and radius, and on each
    // operation: 1e-6 of the largest magnitude covers it).
    std::vector<float>     cellX(celled + 4, 0.0f);
    std::vector<float>     cellY(celled + 4, 0.0f);
    std::vector<float>     cellZ(celled + 4, 0.0f);
    std::vector<float>     cellR(celled + 4, 0.0f);
    std::vector<IndexType> cellTriangles(3 * celled);
    std::vector<double>    cellCorners(9 * celled);
    std::vector<float>     cellBoxes(6 * celled);
    parallel(celled, [&](SizeValueType begin, SizeValueType end) {
      for (SizeValueType i = begin; i < end; ++i)
      {
        const IndexType   t = m_CellOrder[i];
        const IndexType * v = m_Triangles.data() + 3 * t;
        std::copy_n(m_Spheres.data() + 4 * t, 4, cellSpheres.data() + 4 * i);
        cellX[i] = static_cast<float>(m_Spheres[4 * t]);
        cellY[i] = static_cast<float>(m_Spheres[4 * t + 1]);
        cellZ[i] = static_cast<float>(m_Spheres[4 * t + 2]);
        cellR[i] = static_cast<float>(m_Spheres[4 * t + 3]);
        std::copy_n(v, 3, cellTriangles.data() + 3 * i);
        for (unsigned int k = 0; k < 3; ++k)
        {
          std::copy_n(x + 3 * v[k], 3, cellCorners.data() + 9 * i + 3 * k);
        }
        std::copy_n(boxes.data() + 6 * t, 6, cellBoxes.data() + 6 * i);
      }
    });
    // A lower bound of the distance at the reference of a pair whose
    // spheres come within R and that shares no vertex (spheres st, su,
    // boxes bt, bu, corners a, b: 3 points each): the larger of the
    // bounding spheres' gap and the gap between the triangles' projections
    // on the line of their centroids (the exact distance is computed when a
    // step needs it, Constrain()); the pair is a candidate when its boxes
    // overlap and the bound is below R.
    const auto consider = [radius](SizeValueType       t,
                                   SizeValueType       u,
                                   const double *      st,
                                   const double *      su,
                                   const float *       bt,
                                   const float *       bu,
                                   const double *      a,
                                   const double *      b,
                                   std::vector<Pair> & out) {
      if (bt[0] > bu[3] || bu[0] > bt[3] || bt[1] > bu[4] || bu[1] > bt[4] || bt[2] > bu[5] || bu[2] > bt[5])
      {
        return;
      }
      double e[3];
      SurfaceCollisionDetail::Subtract(su, st, e);
      const double centres = std::sqrt(SurfaceCollisionDetail::Dot(e, e));
      double       gap = centres - st[3] - su[3];
      if (centres > 0.0)
      {
        double top = -std::numeric_limits<double>::infinity();
        double bottom = std::numeric_limits<double>::infinity();
        for (unsigned int k = 0; k < 3; ++k)
        {
          top = std::max(top, SurfaceCollisionDetail::Dot(a + 3 * k, e));
          bottom = std::min(bottom, SurfaceCollisionDetail::Dot(b + 3 * k, e));
        }
        gap = std::max(gap, (bottom - top) / centres * (1.0 - 1e-12) - 1e-12 * centres);
      }
      if (gap >= radius)
      {
        return;
      }
      out.push_back({ static_cast<IndexType>(t), static_cast<IndexType>(u), RoundDown(std::max(gap, 0.0)) });
    };
    double largestMagnitude = 0.0;
    for (unsigned int k = 0; k < 3; ++k)
    {
      largestMagnitude = std::max({ largestMagnitude, std::abs(lower[k]), std::abs(upper[k]) });
    }
    const auto floatReach =
      static_cast<float>(radius + 1e-6 * (largestMagnitude + radius + 2.0 * typicalRadius + 1.0)) * (1.0f + 1e-6f);
    const CellLevel &              base = m_Levels[0];
    const SizeValueType            baseCells = base.keys.size();
    const SizeValueType            cellBlocks = (baseCells + 1023) / 1024;
    std::vector<std::vector<Pair>> pairs(cellBlocks + 1);
    parallel(baseCells, [&](SizeValueType begin, SizeValueType end) {
      auto &                 out = pairs[begin / 1024];
      std::vector<IndexType> hits;
      for (SizeValueType s = begin; s < end; ++s)
      {
        for (IndexType c = base.neighbourOffsets[s]; c < base.neighbourOffsets[s + 1]; ++c)
        {
          const IndexType other = base.neighbours[c];
          if (other < s)
          {
            continue;
          }
          const IndexType last = m_CellOffsets[other + 1];
          for (IndexType i = m_CellOffsets[s]; i < m_CellOffsets[s + 1]; ++i)
          {
            const double *  si = cellSpheres.data() + 4 * i;
            const double    reachOfI = radius + si[3];
            const IndexType first = other == s ? i + 1 : m_CellOffsets[other];
            // The pairs whose spheres come within R: the float filter, then
            // the double test on its hits (about one in seven passes).
            hits.resize(std::max<SizeValueType>(hits.size(), last - std::min(first, last) + 4));
            const SizeValueType count = SurfaceCollisionDetail::SpheresWithin(cellX.data(),
                                                                              cellY.data(),
                                                                              cellZ.data(),
                                                                              cellR.data(),
                                                                              first,
                                                                              last,
                                                                              cellX[i],
                                                                              cellY[i],
                                                                              cellZ[i],
                                                                              floatReach + cellR[i],
                                                                              hits.data());
            for (SizeValueType h = 0; h < count; ++h)
            {
              const IndexType j = hits[h];
              const double *  sj = cellSpheres.data() + 4 * j;
              {
                const double e0 = si[0] - sj[0];
                const double e1 = si[1] - sj[1];
                const double e2 = si[2] - sj[2];
                const double reach = reachOfI + sj[3];
                if (!(e0 * e0 + e1 * e1 + e2 * e2 < reach * reach * (1.0 + 1e-12)))
                {
                  continue;
                }
              }
              // A shared vertex (half of the pairs whose spheres come
              // within R): no candidate.
              if (SurfaceCollisionDetail::ShareVertex(cellTriangles.data() + 3 * i, cellTriangles.data() + 3 * j))
              {
                continue;
              }
              consider(m_CellOrder[i],
                       m_CellOrder[j],
                       si,
                       sj,
                       cellBoxes.data() + 6 * i,
                       cellBoxes.data() + 6 * j,
                       cellCorners.data() + 9 * i,
                       cellCorners.data() + 9 * j,
                       out);
            }
          }
        }
      }
    });
    // The grid of every triangle's box is built only when a step needs it
    // (EnsureReferenceGrid()): building it at every rebuild for a few large
    // triangles was a tenth of the rebuild.
    m_ReferenceGrid.Clear();
    m_ReferenceGridBuilt = false;
    if (!m_Large.empty())
    {
      auto &     out = pairs[cellBlocks];
      const auto corners = [x](const IndexType * v, double * c) {
        for (unsigned int k = 0; k < 3; ++k)
        {
          std::copy_n(x + 3 * v[k], 3, c + 3 * k);
        }
      };
      // The large triangles' boxes, for a grid of their own (their pairs).
      std::vector<float> largeBoxes(6 * m_Large.size());
      for (SizeValueType l = 0; l < m_Large.size(); ++l)
      {
        std::copy_n(boxes.data() + 6 * m_Large[l], 6, largeBoxes.data() + 6 * l);
      }
      SurfaceCollisionDetail::BoxGrid largeGrid;
      largeGrid.Build(largeBoxes.data(), m_Large.size());
      const double limit = static_cast<double>((uint64_t{ 1 } << KeyBits) - 1);
      const auto   keyOf = [&](double c, unsigned int k) {
        return std::min(limit, std::max(0.0, std::floor((c - lower[k]) / cellSize) + 1.0));
      };
      for (SizeValueType l = 0; l < m_Large.size(); ++l)
      {
        const IndexType   t = m_Large[l];
        const IndexType * vt = m_Triangles.data() + 3 * t;
        const double *    st = m_Spheres.data() + 4 * t;
        double            a[9];
        corners(vt, a);
        const auto test = [&](IndexType u) {
          const IndexType * vu = m_Triangles.data() + 3 * u;
          const double *    su = m_Spheres.data() + 4 * u;
          double            e[3];
          SurfaceCollisionDetail::Subtract(su, st, e);
          const double reach = radius + st[3] + su[3];
          if (SurfaceCollisionDetail::ShareVertex(vt, vu) ||
              SurfaceCollisionDetail::Dot(e, e) >= reach * reach * (1.0 + 1e-12))
          {
            return;
          }
          double b[9];
          corners(vu, b);
          consider(t, u, st, su, boxes.data() + 6 * t, boxes.data() + 6 * u, a, b, out);
        };
        // The triangles of the cells: their centroids are within
        // R + r_t + (the cells' largest radius) of t's along each axis when
        // their spheres come within R.
        const double reach = (radius + st[3] + typicalRadius) * (1.0 + 1e-9);
        uint64_t     lo[3], hi[3];
        for (unsigned int k = 0; k < 3; ++k)
        {
          lo[k] = static_cast<uint64_t>(keyOf(st[k] - reach, k));
          hi[k] = static_cast<uint64_t>(keyOf(st[k] + reach, k));
        }
        for (uint64_t i = lo[0]; i <= hi[0]; ++i)
        {
          for (uint64_t j = lo[1]; j <= hi[1]; ++j)
          {
            const uint64_t first = Key(i, j, lo[2]);
            const uint64_t last = Key(i, j, hi[2]);
            for (auto c = std::lower_bound(base.keys.begin(), base.keys.end(), first);
                 c != base.keys.end() && *c <= last;
                 ++c)
            {
              const auto cell = static_cast<SizeValueType>(c - base.keys.begin());
              for (IndexType o = m_CellOffsets[cell]; o < m_CellOffsets[cell + 1]; ++o)
              {
                test(m_CellOrder[o]);
              }
            }
          }
        }
        // The other large triangles (each pair once).
        largeGrid.ForEachOverlapOfBox(largeBoxes.data() + 6 * l, l, [&](SizeValueType other) {
          if (other > l)
          {
            test(m_Large[other]);
          }
        });
      }
    }
    m_CandidateOffsets.assign(numberOfTriangles + 1, 0);
    for (const auto & block : pairs)
    {
      for (const Pair & p : block)
      {
        ++m_CandidateOffsets[p.t + 1];
        ++m_CandidateOffsets[p.u + 1];
      }
    }
    for (SizeValueType t = 0; t < numberOfTriangles; ++t)
    {
      m_CandidateOffsets[t + 1] += m_CandidateOffsets[t];
    }
    m_Candidates.resize(m_CandidateOffsets[numberOfTriangles]);
    m_CandidateGaps.resize(m_Candidates.size());
    m_CandidateExact.assign(m_Candidates.size(), 0);
    {
      std::vector<SizeValueType> fill(m_CandidateOffsets.begin(), m_CandidateOffsets.end() - 1);
      for (const auto & block : pairs)
      {
        for (const Pair & p : block)
        {
          m_Candidates[fill[p.t]] = p.u;
          m_CandidateGaps[fill[p.t]++] = p.gap;
          m_Candidates[fill[p.u]] = p.t;
          m_CandidateGaps[fill[p.u]++] = p.gap;
        }
      }
    }
    m_Clearance.resize(numberOfTriangles);
    parallel(numberOfTriangles, [&](SizeValueType begin, SizeValueType end) {
      for (SizeValueType t = begin; t < end; ++t)
      {
        double smallest = radius;
        for (SizeValueType c = m_CandidateOffsets[t]; c < m_CandidateOffsets[t + 1]; ++c)
        {
          smallest = std::min(smallest, static_cast<double>(m_CandidateGaps[c]));
        }
        m_Clearance[t] = RoundDown(smallest - d);
      }
    });
    // The pairs sharing one vertex: their gaps at the reference (exact), and
    // the clearance of their triangles against the contact distance.
    // A bound carried over from the former reference while it has lost at
    // most SharedLoss R since it was computed (a lower bound lowers the
    // clearances, so that more triangles are tested, but never misses a
    // pair); otherwise computed, to SharedSlack R so that the next rebuilds
    // can carry it.
    std::atomic<SizeValueType> computed{ 0 };
    parallel(m_SharedGaps.size(), [&](SizeValueType begin, SizeValueType end) {
      SizeValueType count = 0;
      for (SizeValueType q = begin; q < end; ++q)
      {
        m_SharedExact[q] = 0;
        if (carry)
        {
          const float carried = this->CarriedSharedGap(q);
          if (static_cast<double>(carried) >= static_cast<double>(m_SharedComputed[q]) - SharedLoss * radius)
          {
            m_SharedGaps[q] = carried;
            continue;
          }
        }
        ++count;
        m_SharedGaps[q] = RoundDown(this->SharedGapLowerBound(q, x, SharedSlack * radius));
        m_SharedComputed[q] = m_SharedGaps[q];
      }
      computed += count;
    });
    m_NumberOfComputedSharedGaps = computed;
    parallel(numberOfTriangles, [&](SizeValueType begin, SizeValueType end) {
      for (SizeValueType t = begin; t < end; ++t)
      {
        for (IndexType k = m_SharedOffsets[t]; k < m_SharedOffsets[t + 1]; ++k)
        {
          m_Clearance[t] = std::min(
            m_Clearance[t], RoundDown(static_cast<double>(m_SharedGaps[m_SharedOfTriangle[k]]) - m_ContactDistance));
        }
      }
    });

    // Coarser levels until every cell neighbours every other.
    const uint64_t mask = (uint64_t{ 1 } << KeyBits) - 1;
    const auto     spread = [mask](const std::vector<uint64_t> & levelKeys) {
      uint64_t largest = 0;
      for (unsigned int k = 0; k < 3; ++k)
      {
        uint64_t lo = mask, hi = 0;
        for (const uint64_t key : levelKeys)
        {
          const uint64_t c = (key >> (KeyBits * (2 - k))) & mask;
          lo = std::min(lo, c);
          hi = std::max(hi, c);
        }
        largest = std::max(largest, hi - lo);
      }
      return largest;
    };
    while (spread(m_Levels.back().keys) > 1)
    {
      CellLevel & finer = m_Levels.back();
      CellLevel   coarser;
      coarser.cellSize = 2.0 * finer.cellSize;
      std::vector<uint64_t> parentKeys(finer.keys.size());
      for (SizeValueType s = 0; s < finer.keys.size(); ++s)
      {
        const uint64_t key = finer.keys[s];
        parentKeys[s] = Key(((key >> (2 * KeyBits)) & mask) >> 1, ((key >> KeyBits) & mask) >> 1, (key & mask) >> 1);
      }
      coarser.keys = parentKeys;
      std::sort(coarser.keys.begin(), coarser.keys.end());
      coarser.keys.erase(std::unique(coarser.keys.begin(), coarser.keys.end()), coarser.keys.end());
      finer.parents.resize(finer.keys.size());
      for (SizeValueType s = 0; s < finer.keys.size(); ++s)
      {
        finer.parents[s] = static_cast<IndexType>(
          std::lower_bound(coarser.keys.begin(), coarser.keys.end(), parentKeys[s]) - coarser.keys.begin());
      }
      m_Levels.push_back(std::move(coarser));
      FindNeighbours(m_Levels.back());
    }
    for (SizeValueType l = 1; l < m_Levels.size(); ++l)
    {
      GroupsOfKeys(m_Levels[l - 1].parents, 1, m_Levels[l].keys.size(), m_Levels[l].childOffsets, m_Levels[l].children);
    }
    // The largest triangle radius of each cell and of the 27 around it.
    m_Levels[0].radii.assign(m_Levels[0].keys.size(), 0.0);
    for (const IndexType t : m_CellOrder)
    {
      double & r = m_Levels[0].radii[m_TriangleCell[t]];
      r = std::max(r, m_Spheres[4 * t + 3]);
    }
    for (SizeValueType l = 1; l < m_Levels.size(); ++l)
    {
      const CellLevel & finer = m_Levels[l - 1];
      m_Levels[l].radii.assign(m_Levels[l].keys.size(), 0.0);
      for (SizeValueType c = 0; c < finer.keys.size(); ++c)
      {
        double & r = m_Levels[l].radii[finer.parents[c]];
        r = std::max(r, finer.radii[c]);
      }
    }
    for (CellLevel & level : m_Levels)
    {
      level.neighbourRadii.assign(level.keys.size(), 0.0);
      for (SizeValueType c = 0; c < level.keys.size(); ++c)
      {
        for (IndexType k = level.neighbourOffsets[c]; k < level.neighbourOffsets[c + 1]; ++k)
        {
          level.neighbourRadii[c] = std::max(level.neighbourRadii[c], level.radii[level.neighbours[k]]);
        }
      }
    }
    // Smallest clearance of each level-0 cell.
    m_CellClearance.resize(m_Levels[0].keys.size());
    for (SizeValueType s = 0; s < m_Levels[0].keys.size(); ++s)
    {
      float smallest = std::numeric_limits<float>::infinity();
      for (IndexType i = m_CellOffsets[s]; i < m_CellOffsets[s + 1]; ++i)
      {
        smallest = std::min(smallest, m_Clearance[m_CellOrder[i]]);
      }
      m_CellClearance[s] = smallest;
    }
    m_VertexDelta.resize(6 * n);
    m_TriangleDelta.resize(6 * numberOfTriangles);
    m_Active.assign(numberOfTriangles, 0);
    m_IsDeferred.assign(numberOfTriangles, 0);
    m_Deferred.clear();
    m_SpecialGridBuilt = false;
    m_DeferredSum = 0;
    m_DeferredWork = 0;
    m_IndexValid = true;
    return true;
  }

  /** The bounds of the class documentation at the proposed positions y:
   * Exceeded when a level's bound or some triangle's rho reaches R - d
   * (the index must be rebuilt), otherwise m_Active marks the triangles
   * whose rho reaches their clearance. */
  template <typename TParallel>
  BoundStatus
  Bound(const double * y, TParallel && parallel, const double * x = nullptr)
  {
    const SizeValueType n = m_NumberOfPoints;
    const double        d = std::max(m_MinimumDistance, m_ContactDistance);
    std::atomic<bool>   finite{ true };
    parallel(n, [&](SizeValueType begin, SizeValueType end) {
      // v - v is 0 for a finite v and NaN otherwise: one test per block.
      double check = 0.0;
      for (SizeValueType i = begin; i < end; ++i)
      {
        float * box = m_VertexDelta.data() + 6 * i;
        for (unsigned int k = 0; k < 3; ++k)
        {
          double delta = y[3 * i + k] - m_Reference[3 * i + k];
          double low = delta;
          if (x != nullptr)
          {
            // The box of x - r and y - r: every state between x and y.
            const double other = x[3 * i + k] - m_Reference[3 * i + k];
            low = std::min(delta, other);
            delta = std::max(delta, other);
          }
          check += (delta - delta) + (low - low);
          SurfaceCollisionDetail::OutwardFloats(low, delta, box[k], box[3 + k]);
        }
      }
      if (!(check == 0.0))
      {
        finite = false;
      }
    });
    if (!finite)
    {
      return BoundStatus::NonFinite;
    }
    // Triangles' and level-0 cells' boxes.
    CellLevel &         base = m_Levels[0];
    const SizeValueType baseCells = base.keys.size();
    m_CellDeferred.assign(baseCells, 0);
    m_CellDiameter.resize(baseCells);
    parallel(baseCells, [&](SizeValueType begin, SizeValueType end) {
      for (SizeValueType s = begin; s < end; ++s)
      {
        float * cellBox = base.boxes.data() + 6 * s;
        EmptyBox(cellBox);
        for (IndexType i = m_CellOffsets[s]; i < m_CellOffsets[s + 1]; ++i)
        {
          const IndexType   t = m_CellOrder[i];
          const IndexType * v = m_Triangles.data() + 3 * t;
          float *           box = m_TriangleDelta.data() + 6 * t;
          TriangleOfVertexBoxes(v, box);
          Unite(cellBox, box);
        }
        m_CellDiameter[s] = LargestDistance(cellBox, cellBox);
      }
    });
    // The large triangles' boxes, and the box of every displacement.
    EmptyBox(m_GlobalDelta);
    for (const IndexType t : m_Large)
    {
      const IndexType * v = m_Triangles.data() + 3 * t;
      float *           box = m_TriangleDelta.data() + 6 * t;
      std::copy(m_VertexDelta.data() + 6 * v[0], m_VertexDelta.data() + 6 * v[0] + 6, box);
      Unite(box, m_VertexDelta.data() + 6 * v[1]);
      Unite(box, m_VertexDelta.data() + 6 * v[2]);
      Unite(m_GlobalDelta, box);
    }
    for (SizeValueType l = 1; l < m_Levels.size(); ++l)
    {
      CellLevel &       level = m_Levels[l];
      const CellLevel & finer = m_Levels[l - 1];
      for (SizeValueType s = 0; s < level.keys.size(); ++s)
      {
        EmptyBox(level.boxes.data() + 6 * s);
      }
      for (SizeValueType s = 0; s < finer.keys.size(); ++s)
      {
        Unite(level.boxes.data() + 6 * finer.parents[s], finer.boxes.data() + 6 * s);
      }
    }
    std::atomic<bool> exceeded{ false };
    for (SizeValueType l = 0; l < m_Levels.size(); ++l)
    {
      CellLevel & level = m_Levels[l];
      // Pairs first met at this level are at least 2^(l-1) s less their
      // triangles' radii apart.
      const double separation = l == 0 ? 0.0 : m_Levels[l - 1].cellSize;
      parallel(level.keys.size(), [&](SizeValueType begin, SizeValueType end) {
        bool out = false;
        for (SizeValueType s = begin; s < end; ++s)
        {
          float * u = level.unions.data() + 6 * s;
          EmptyBox(u);
          for (IndexType c = level.neighbourOffsets[s]; c < level.neighbourOffsets[s + 1]; ++c)
          {
            Unite(u, level.boxes.data() + 6 * level.neighbours[c]);
          }
          if (l > 0 && !(LargestDistance(level.boxes.data() + 6 * s, u) <
                         separation - (level.radii[s] + level.neighbourRadii[s]) * (1.0 + 1e-9) - d))
          {
            // Level 1 at the resolution of level 0: defers the triangles of
            // the level-0 cells it does not clear. Above: a rebuild.
            if (l == 1)
            {
              this->DeferLevelOneCell(s, d);
            }
            else
            {
              out = true;
            }
          }
        }
        if (out)
        {
          exceeded = true;
        }
      });
      if (exceeded)
      {
        return BoundStatus::Exceeded;
      }
    }
    const CellLevel & top = m_Levels.back();
    for (SizeValueType c = 0; c < top.keys.size(); ++c)
    {
      Unite(m_GlobalDelta, top.boxes.data() + 6 * c);
    }
    // Level 0: rho of each triangle against its cell's neighbourhood. A
    // triangle whose rho reaches R - d is deferred: its pairs that are no
    // candidates may have come within d, so it queries the grid of the
    // boxes at the reference, as the large triangles do (Constrain()),
    // instead of the index being rebuilt for a few triangles that move
    // against the rest (a converging surface). Too many of them, at this
    // step or summed over the steps since the rebuild, and the index is
    // rebuilt: each costs a grid query per step, a rebuild about as much
    // per triangle.
    const double                        radiusLimit = m_Radius - d;
    const SizeValueType                 blocks = (baseCells + 1023) / 1024;
    std::vector<std::vector<IndexType>> deferred(blocks);
    parallel(baseCells, [&](SizeValueType begin, SizeValueType end) {
      auto & out = deferred[begin / 1024];
      for (SizeValueType s = begin; s < end; ++s)
      {
        const float * u = base.unions.data() + 6 * s;
        const double  cellRho = LargestDistance(base.boxes.data() + 6 * s, u);
        const bool    cellClear = cellRho < static_cast<double>(m_CellClearance[s]);
        const bool    cellInside = cellRho < radiusLimit;
        for (IndexType i = m_CellOffsets[s]; i < m_CellOffsets[s + 1]; ++i)
        {
          const IndexType t = m_CellOrder[i];
          if (cellClear)
          {
            m_Active[t] = 0;
            m_IsDeferred[t] = m_CellDeferred[s];
            if (m_CellDeferred[s])
            {
              out.push_back(t);
            }
            continue;
          }
          const double rho = LargestDistance(m_TriangleDelta.data() + 6 * t, u);
          const bool   defer = m_CellDeferred[s] || (!cellInside && !(rho < radiusLimit) && this->DeferByRho(t, s, d));
          m_IsDeferred[t] = defer ? 1 : 0;
          if (defer)
          {
            out.push_back(t);
          }
          m_Active[t] = rho < static_cast<double>(m_Clearance[t]) ? 0 : 1;
        }
      }
    });
    m_Deferred.clear();
    for (const auto & block : deferred)
    {
      m_Deferred.insert(m_Deferred.end(), block.begin(), block.end());
    }
    m_SpecialGridBuilt = false;
    const SizeValueType numberOfTriangles = this->GetNumberOfTriangles();
    if (x == nullptr)
    {
      m_DeferredSum += m_Deferred.size();
    }
    if (m_Deferred.size() > std::max<SizeValueType>(numberOfTriangles / DeferredPerStep, 64) ||
        m_DeferredSum > std::max<SizeValueType>(numberOfTriangles / DeferredPerRebuild, 1024) ||
        m_DeferredWork > DeferredVisitsPerTriangle * std::max<SizeValueType>(numberOfTriangles, 1024))
    {
      return BoundStatus::Exceeded;
    }
    return BoundStatus::Bounded;
  }

  /** Of two level-0 cells whose pairs of triangles are not bounded, the
   * one whose triangles are deferred (so that each pair has one side that
   * queries the grid, not both): the one whose displacement box is the
   * larger (it moved against the other), the lower index on a tie. */
  bool
  Prefer(SizeValueType s, SizeValueType c) const
  {
    return m_CellDiameter[s] > m_CellDiameter[c] || (m_CellDiameter[s] == m_CellDiameter[c] && s < c);
  }

  /** Triangle t of level-0 cell s, whose rho reached R - d, is deferred
   * when its motion against the box of a neighbouring cell c of which s is
   * preferred (Prefer()), or against another triangle u of its own cell
   * with a smaller displacement box (the lower index on a tie), reaches
   * R - d. A pair (t, u) whose motion reaches R - d has t's motion against
   * u (and u's cell) and u's against t (and t's cell) reach it, so the
   * preferred side of the two is deferred: the ones that moved, not every
   * triangle around them. */
  bool
  DeferByRho(SizeValueType t, SizeValueType s, double d) const
  {
    const CellLevel & base = m_Levels[0];
    const float *     bt = m_TriangleDelta.data() + 6 * t;
    const double      limit = m_Radius - d;
    for (IndexType k = base.neighbourOffsets[s]; k < base.neighbourOffsets[s + 1]; ++k)
    {
      const IndexType c = base.neighbours[k];
      if (c != s && this->Prefer(s, c) && !(LargestDistance(bt, base.boxes.data() + 6 * c) < limit))
      {
        return true;
      }
    }
    const double diameter = LargestDistance(bt, bt);
    for (IndexType i = m_CellOffsets[s]; i < m_CellOffsets[s + 1]; ++i)
    {
      const IndexType u = m_CellOrder[i];
      const float *   bu = m_TriangleDelta.data() + 6 * u;
      if (u == t || !(LargestDistance(bt, bu) >= limit))
      {
        continue;
      }
      const double other = LargestDistance(bu, bu);
      if (diameter > other || (diameter == other && t < u))
      {
        return true;
      }
    }
    return false;
  }

  /** The pairs of level 1 of the pyramid at the resolution of level 0, for
   * a level-1 cell \a cell whose own test failed: every pair of a triangle
   * of one of its level-0 cells s with a triangle of a level-0 cell c that
   * is not a neighbour of s but whose parent neighbours s's parent. Two
   * such cells, with coordinates differing by D_k along axis k, hold
   * centroids at least h sqrt(sum_k max(0, |D_k| - 1)^2) apart (h the
   * level-0 cell size), so their triangles are at least that less the
   * cells' largest radii apart: a bound per pair of cells, from their own
   * radii and displacement boxes, instead of the level-1 cell's union over
   * 27 cells of twice the size and the largest radius around it. A pair of
   * cells that this does not clear fails the level-1 test of both parents,
   * so it is seen from both sides; the preferred cell of the two
   * (Prefer()) is marked (m_CellDeferred): its triangles are deferred
   * (Bound()), i.e. query the grid of the boxes at the reference for every
   * pair that may have come within d. (A level-1 failure made most of the
   * rebuilds of a converging brain surface.) */
  void
  DeferLevelOneCell(SizeValueType cell, double d)
  {
    const CellLevel & base = m_Levels[0];
    const CellLevel & one = m_Levels[1];
    const uint64_t    mask = (uint64_t{ 1 } << KeyBits) - 1;
    const double      h = base.cellSize;
    const auto gap = [](int64_t delta) { return static_cast<double>(std::max<int64_t>(0, std::abs(delta) - 1)); };
    for (IndexType o = one.childOffsets[cell]; o < one.childOffsets[cell + 1]; ++o)
    {
      const IndexType s = one.children[o];
      const uint64_t  key = base.keys[s];
      const auto      ci = static_cast<int64_t>((key >> (2 * KeyBits)) & mask);
      const auto      cj = static_cast<int64_t>((key >> KeyBits) & mask);
      const auto      ck = static_cast<int64_t>(key & mask);
      const float *   bs = base.boxes.data() + 6 * s;
      const auto      clear = [&]() {
        for (int64_t di = -3; di <= 3; ++di)
        {
          for (int64_t dj = -3; dj <= 3; ++dj)
          {
            if (ci + di < 0 || cj + dj < 0)
            {
              continue;
            }
            const auto i = static_cast<uint64_t>(ci + di);
            const auto j = static_cast<uint64_t>(cj + dj);
            const auto first = Key(i, j, static_cast<uint64_t>(std::max<int64_t>(0, ck - 3)));
            const auto last = Key(i, j, static_cast<uint64_t>(ck + 3));
            for (auto c = std::lower_bound(base.keys.begin(), base.keys.end(), first);
                 c != base.keys.end() && *c <= last;
                 ++c)
            {
              const int64_t dk = static_cast<int64_t>(*c & mask) - ck;
              if ((std::abs(di) <= 1 && std::abs(dj) <= 1 && std::abs(dk) <= 1) ||
                  std::abs(((ci + di) >> 1) - (ci >> 1)) > 1 || std::abs(((cj + dj) >> 1) - (cj >> 1)) > 1 ||
                  std::abs(((ck + dk) >> 1) - (ck >> 1)) > 1)
              {
                continue; // level 0's pairs, or level 2's and above
              }
              const double cells = std::sqrt(gap(di) * gap(di) + gap(dj) * gap(dj) + gap(dk) * gap(dk));
              const auto   other = static_cast<SizeValueType>(c - base.keys.begin());
              // At least level 1's own separation less the radii (cells >= 1,
              // radii no larger), so that a pair this does not clear fails
              // the level-1 test of both its cells' parents (Prefer()).
              const double separation = h * cells - (base.radii[s] + base.radii[other]) * (1.0 + 1e-9) - d;
              if (this->Prefer(s, other) && !(LargestDistance(bs, base.boxes.data() + 6 * other) < separation))
              {
                return false;
              }
            }
          }
        }
        return true;
      };
      if (!clear())
      {
        m_CellDeferred[s] = 1;
      }
    }
  }

  /** The uniform grid of the triangles' boxes swept from x to y, widened by
   * d/2: two triangles whose boxes do not overlap are at least d apart in
   * every state between x and y that the reductions make. */
  template <typename TParallel>
  void
  BuildSweptGrid(const double * x, const double * y, double d, TParallel && parallel)
  {
    const SizeValueType numberOfTriangles = this->GetNumberOfTriangles();
    m_SweptBoxes.resize(6 * numberOfTriangles);
    parallel(numberOfTriangles, [&](SizeValueType begin, SizeValueType end) {
      for (SizeValueType t = begin; t < end; ++t)
      {
        double lo[3], hi[3], lo2[3], hi2[3];
        TriangleBox(x, m_Triangles.data() + 3 * t, lo, hi);
        TriangleBox(y, m_Triangles.data() + 3 * t, lo2, hi2);
        for (unsigned int k = 0; k < 3; ++k)
        {
          lo[k] = std::min(lo[k], lo2[k]);
          hi[k] = std::max(hi[k], hi2[k]);
        }
        SurfaceCollisionDetail::StoreBox(lo, hi, 0.5 * d, m_SweptBoxes.data() + 6 * t);
      }
    });
    m_SweptGrid.Build(m_SweptBoxes.data(), numberOfTriangles);
  }

  /** m as a float not below it (0 stays 0). */
  static float
  RoundUp(double m)
  {
    const float f = static_cast<float>(m);
    return static_cast<double>(f) >= m ? f : SurfaceCollisionDetail::NextFloatUp(f);
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

  /** Per point, the triangles that use it (a CSR table, each point's
   * triangles in increasing order), made once per SetSurface() when first
   * needed. Not thread-safe: called before the parallel loops that read it. */
  void
  EnsureVertexTriangles()
  {
    if (!m_VertexTrianglesReady)
    {
      GroupsOfKeys(m_Triangles, 3, m_NumberOfPoints, m_VertexTriangleOffsets, m_VertexTriangles);
      m_VertexTrianglesReady = true;
    }
  }

  /** Around point a, the other two points of each triangle of its fan
   * (in the order of the fan's list), as (a, after, before) in the
   * triangle's own order. EnsureVertexTriangles() must have run. */
  void
  FanNeighbours(SizeValueType a, std::vector<IndexType> & after, std::vector<IndexType> & before) const
  {
    const SizeValueType first = m_VertexTriangleOffsets[a];
    const SizeValueType n = m_VertexTriangleOffsets[a + 1] - first;
    after.resize(n);
    before.resize(n);
    for (SizeValueType i = 0; i < n; ++i)
    {
      const IndexType *  vu = m_Triangles.data() + 3 * static_cast<SizeValueType>(m_VertexTriangles[first + i]);
      const unsigned int j = vu[0] == a ? 0 : (vu[1] == a ? 1 : 2);
      after[i] = vu[(j + 1) % 3];
      before[i] = vu[(j + 2) % 3];
    }
  }

  /** The tables of the pairs of triangles sharing exactly one vertex (in
   * one fan, not across an edge), made once per SetSurface() when first
   * needed: each pair once, t < u, and per triangle the pairs it is in. In
   * blocks (in parallel with a threader), concatenated in order: the same
   * list whatever the threads. */
  void
  EnsureSharedPairs(const SurfaceCollisionDetail::ParallelBlocks & parallel)
  {
    if (m_SharedPairsReady)
    {
      return;
    }
    this->EnsureVertexTriangles();
    const SizeValueType                 numberOfPoints = m_NumberOfPoints;
    const SizeValueType                 numberOfTriangles = this->GetNumberOfTriangles();
    constexpr SizeValueType             block = SurfaceCollisionDetail::ParallelBlocks::Block;
    std::vector<std::vector<IndexType>> blockPairs;
    if (!m_RepeatedPoint)
    {
      // Point by point: two triangles of a's fan share a vertex besides a
      // when one's after or before is the other's.
      blockPairs.resize((numberOfPoints + block - 1) / block);
      parallel(numberOfPoints, [&](SizeValueType begin, SizeValueType end) {
        auto &                 pairs = blockPairs[begin / block];
        std::vector<IndexType> after;
        std::vector<IndexType> before;
        for (SizeValueType a = begin; a < end; ++a)
        {
          this->FanNeighbours(a, after, before);
          const IndexType *   fan = m_VertexTriangles.data() + m_VertexTriangleOffsets[a];
          const SizeValueType n = after.size();
          // A fan lists its triangles in increasing order: t < u.
          for (SizeValueType i = 0; i < n; ++i)
          {
            for (SizeValueType j = i + 1; j < n; ++j)
            {
              if (after[i] != after[j] && after[i] != before[j] && before[i] != after[j] && before[i] != before[j])
              {
                pairs.push_back(fan[i]);
                pairs.push_back(fan[j]);
              }
            }
          }
        }
      });
    }
    else
    {
      // A triangle repeating a point is listed twice in that point's fan:
      // triangle by triangle instead, as SharedVertices() counts.
      blockPairs.resize((numberOfTriangles + block - 1) / block);
      parallel(numberOfTriangles, [&](SizeValueType begin, SizeValueType end) {
        auto & pairs = blockPairs[begin / block];
        for (SizeValueType t = begin; t < end; ++t)
        {
          const IndexType * vt = m_Triangles.data() + 3 * t;
          for (unsigned int k = 0; k < 3; ++k)
          {
            const IndexType a = vt[k];
            for (SizeValueType f = m_VertexTriangleOffsets[a]; f < m_VertexTriangleOffsets[a + 1]; ++f)
            {
              const IndexType u = m_VertexTriangles[f];
              if (u > t && SharedVertices(vt, m_Triangles.data() + 3 * static_cast<SizeValueType>(u)) == 1)
              {
                pairs.push_back(static_cast<IndexType>(t));
                pairs.push_back(u);
              }
            }
          }
        }
      });
    }
    m_SharedPairs.clear();
    for (const auto & pairs : blockPairs)
    {
      m_SharedPairs.insert(m_SharedPairs.end(), pairs.begin(), pairs.end());
    }
    const SizeValueType numberOfSharedPairs = m_SharedPairs.size() / 2;
    GroupsOfKeys(m_SharedPairs, 2, numberOfTriangles, m_SharedOffsets, m_SharedOfTriangle);
    // The other triangle of each entry, read at every step without a visit
    // to the pair.
    m_SharedPartner.resize(m_SharedOfTriangle.size());
    parallel(numberOfTriangles, [&](SizeValueType begin, SizeValueType end) {
      for (SizeValueType t = begin; t < end; ++t)
      {
        for (IndexType k = m_SharedOffsets[t]; k < m_SharedOffsets[t + 1]; ++k)
        {
          m_SharedPartner[k] = this->OtherOfShared(m_SharedOfTriangle[k], t);
        }
      }
    });
    m_SharedGaps.assign(numberOfSharedPairs, 0.0f);
    m_SharedExact.assign(numberOfSharedPairs, 0);
    m_SharedComputed.assign(numberOfSharedPairs, 0.0f);
    m_SharedPairsReady = true;
  }

  SizeValueType m_NumberOfPoints{ 0 };
  bool          m_HasSurface{ false };
  // StarShaped()'s per-point sides, kept between calls.
  mutable std::vector<uint8_t> m_StarSides;
  mutable std::vector<double>  m_FoldDirections; // StarShapedUpToFolds(): unit directions from the centre
  std::vector<IndexType>       m_Triangles;
  std::vector<SizeValueType>   m_VertexTriangleOffsets;
  std::vector<IndexType>       m_VertexTriangles;
  std::vector<IndexType>       m_SharedPairs;      // pairs sharing exactly one vertex: t, u (t < u)
  std::vector<IndexType>       m_SharedOffsets;    // triangle -> range of m_SharedOfTriangle
  std::vector<IndexType>       m_SharedOfTriangle; // the shared pairs each triangle is in
  std::vector<IndexType>       m_SharedPartner;    // per entry of m_SharedOfTriangle, the other triangle
  std::vector<float>           m_SharedGaps;       // per shared pair: a lower bound of its gap at the reference
  std::vector<uint8_t>         m_SharedExact;      // per shared pair: the bound is the exact gap
  std::vector<float>           m_SharedComputed;   // per shared pair: its bound when last computed (not carried)

  bool          m_Closed{ false };               // IsClosedSurface()
  bool          m_RepeatedPoint{ false };        // a triangle of SetSurface() repeats a point
  bool          m_SharedPairsReady{ false };     // EnsureSharedPairs() ran since SetSurface()
  bool          m_VertexTrianglesReady{ false }; // EnsureVertexTriangles() ran since SetSurface()
  bool          m_UseStarCertificate{ true };
  SizeValueType m_NumberOfCertifiedSteps{ 0 };
  SizeValueType m_TotalNumberOfCertifiedSteps{ 0 };
  unsigned int  m_CertificateWait{ 0 };    // calls to skip before the next try
  unsigned int  m_CertificateBackoff{ 0 }; // the last wait
  // CarryCertificate(): the positions of the last certificate without
  // folds, and how far every point may move from them (0: no carrying).
  std::vector<double>  m_CarriedFrom;
  double               m_CarriedMargin{ 0.0 };
  double               m_CarriedCentre[3]{ 0.0, 0.0, 0.0 }; // the certificate's centre
  int                  m_CarriedSign{ 0 };                  // the orientation of its triangles seen from it
  double               m_CarriedRounding{ 0.0 };            // StarShaped()'s bound of the determinants' rounding
  SizeValueType        m_TotalNumberOfTrianglesWithinOwnMargin{ 0 };
  SizeValueType        m_TotalNumberOfPointsWithinOwnMargin{ 0 };
  std::vector<uint8_t> m_CarriedFar; // CarriedTo(): per point, beyond the margin
  // SetPointFans(): the caller's fans (not owned), and CarriedTo()'s list of
  // the points beyond the margin.
  const IndexType *      m_FanOffsets{ nullptr };
  const IndexType *      m_FanNeighbours{ nullptr };
  std::vector<IndexType> m_CarriedFarPoints;
  // CarriedAlongFans(): per point, the square of the least own margin of its
  // triangles (OwnMarginLimit()), computed when the point first goes beyond
  // the carried margin (negative until then), for the carried certificate.
  std::vector<double> m_PointLimits;
  bool                m_PointLimitsReady{ false };
  SizeValueType       m_TotalNumberOfCarriedCertificates{ 0 };
  // CarryNow(): the steps certified by the last carried margin, whether one
  // was computed since the last decision, and the wait before the next.
  SizeValueType m_CarryYield{ 0 };
  bool          m_CarryTried{ false };
  unsigned int  m_CarryWait{ 0 };
  unsigned int  m_CarryBackoff{ 0 };

  // CarryNow(): the step that ended the last carry too soon (0: none, or
  // its wait already ended), and the certified steps since, in a row, 8
  // times shorter.
  double       m_FailedCarryStep{ 0.0 };
  unsigned int m_ShortSteps{ 0 };

  // Certify(): the carried margins of the certificate's pass, per block.
  std::vector<double> m_CarryLeast;

  // The index (see the class documentation).
  bool                            m_IndexValid{ false };
  double                          m_MinimumDistance{ 0.0 };
  double                          m_ContactDistance{ 0.0 };
  double                          m_Radius{ 0.0 };
  SizeValueType                   m_NumberOfRebuilds{ 0 };
  SizeValueType                   m_TotalNumberOfRebuilds{ 0 };
  SizeValueType                   m_NumberOfComputedSharedGaps{ 0 };
  std::vector<double>             m_Reference;
  std::vector<double>             m_Spheres; // per triangle at the reference: centre, radius
  std::vector<IndexType>          m_CandidateOffsets;
  std::vector<IndexType>          m_Candidates;     // both directions
  std::vector<float>              m_CandidateGaps;  // lower bound of the distance at the reference, rounded down
  std::vector<uint8_t>            m_InRound;        // scratch of Constrain(): the triangles of a halving round
  std::vector<uint8_t>            m_CandidateExact; // the gap is the exact distance
  std::vector<float>              m_Clearance;      // per triangle
  std::vector<CellLevel>          m_Levels;
  std::vector<IndexType>          m_CellOrder;   // triangles sorted by level-0 cell
  std::vector<IndexType>          m_CellOffsets; // level-0 cell -> range of m_CellOrder
  std::vector<IndexType>          m_TriangleCell;
  std::vector<IndexType>          m_Large;          // triangles larger than the cells are made for
  std::vector<uint8_t>            m_IsLarge;        // per triangle
  std::vector<float>              m_ReferenceBoxes; // per triangle at the reference, widened by R/2
  SurfaceCollisionDetail::BoxGrid m_ReferenceGrid;  // built when a step needs it (EnsureReferenceGrid())
  bool                            m_ReferenceGridBuilt{ false };
  std::vector<IndexType>          m_SpecialTriangles; // the large and the deferred triangles (EnsureSpecialGrid())
  std::vector<float>              m_SpecialBoxes;     // their boxes at the reference
  SurfaceCollisionDetail::BoxGrid m_SpecialGrid;
  bool                            m_SpecialGridBuilt{ false };
  std::vector<float>              m_CellClearance;

  // Per step.
  std::vector<float>              m_VertexDelta;   // per point: y - r, as a box rounded outward
  std::vector<float>              m_TriangleDelta; // per triangle: box of its points' y - r
  std::vector<uint8_t>            m_Active;
  std::vector<uint8_t>            m_IsDeferred;       // per triangle: rho reached R - d, or level 1 failed (Bound())
  std::vector<uint8_t>            m_CellDeferred;     // per level-0 cell: level 1 did not clear it (Bound())
  std::vector<double>             m_CellDiameter;     // per level-0 cell: its displacement box's diameter (Bound())
  std::vector<IndexType>          m_Deferred;         // those triangles
  SizeValueType                   m_DeferredSum{ 0 }; // deferred triangles summed over the steps since the rebuild
  SizeValueType                   m_NumberOfDeferredTriangles{ 0 };
  SizeValueType                   m_DeferredWork{ 0 }; // boxes visited by their grid queries since the rebuild
  float                           m_GlobalDelta[6]{};
  SizeValueType                   m_NumberOfTestedTriangles{ 0 };
  std::vector<float>              m_SweptBoxes;
  SurfaceCollisionDetail::BoxGrid m_SweptGrid;
  std::vector<uint8_t>            m_Level;
  std::vector<IndexType>          m_ModifiedPoints;
  std::vector<double>             m_ModifiedProposals; // their y as proposed
};
} // end namespace itk

#endif
