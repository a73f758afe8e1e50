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

// SurfaceCollision: the triangle-triangle intersection test and distance on
// known configurations, the index against an all-pairs count, Constrain() on
// fronts pushed through each other; DeformableMeshFilter's
// PreventSelfIntersections on a shrink-wrap whose fronts meet, checked at
// every iteration by an all-pairs test of this file; its bad input.

#include "itkSurfaceCollision.h"
#include "itkDeformableMeshFilter.h"
#include "itkEllipsoidPhantom.h"
#include "itkExternalForceImageFilter.h"
#include "itkMesh.h"

#include "edmTestUtilities.h"

#include "gtest/gtest.h"

#include <array>
#include <cmath>
#include <map>
#include <random>
#include <string>
#include <vector>

namespace
{
using itk::SurfaceCollisionDetail::TriangleDistance;
using itk::SurfaceCollisionDetail::TrianglesIntersect;
using Triangle = std::vector<std::array<double, 3>>;
using MeshType = itk::Mesh<double, 3, itk::DefaultStaticMeshTraits<double, 3, 3, double, double, double>>;

bool
Intersect(const Triangle & a, const Triangle & b)
{
  const double * pa[3] = { a[0].data(), a[1].data(), a[2].data() };
  const double * pb[3] = { b[0].data(), b[1].data(), b[2].data() };
  const bool     ab = TrianglesIntersect(pa, pb);
  EXPECT_EQ(ab, TrianglesIntersect(pb, pa)) << "the test is symmetric";
  return ab;
}

double
Distance(const Triangle & a, const Triangle & b)
{
  const double * pa[3] = { a[0].data(), a[1].data(), a[2].data() };
  const double * pb[3] = { b[0].data(), b[1].data(), b[2].data() };
  const double   ab = TriangleDistance(pa, pb);
  EXPECT_NEAR(ab, TriangleDistance(pb, pa), 1e-15 * (1.0 + ab)) << "the distance is symmetric";
  return ab;
}

// ---------------------------------------------------------------------------
// An independent all-pairs test, written for these tests: Moller-Trumbore
// segment-triangle crossings of the 6 edges, and distances from the closest
// points of segments and triangles by projection (not the component's
// Voronoi-region code), every pair of triangles sharing no vertex, no index.
using Vec = std::array<double, 3>;
Vec
Sub(const Vec & a, const Vec & b)
{
  return { a[0] - b[0], a[1] - b[1], a[2] - b[2] };
}
double
DotV(const Vec & a, const Vec & b)
{
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}
Vec
CrossV(const Vec & a, const Vec & b)
{
  return { a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0] };
}
Vec
Along(const Vec & a, const Vec & b, double t)
{
  return { a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1]), a[2] + t * (b[2] - a[2]) };
}

/** The segment [p, q] meets the triangle (Moller-Trumbore, closed). */
bool
SegmentHitsTriangle(const Vec & p, const Vec & q, const Vec & a, const Vec & b, const Vec & c)
{
  const Vec    direction = Sub(q, p);
  const Vec    e1 = Sub(b, a);
  const Vec    e2 = Sub(c, a);
  const Vec    h = CrossV(direction, e2);
  const double det = DotV(e1, h);
  if (std::abs(det) < 1e-300)
  {
    return false; // parallel: not a crossing (the meshes here are never coplanar)
  }
  const double inv = 1.0 / det;
  const Vec    s = Sub(p, a);
  const double u = inv * DotV(s, h);
  if (u < 0.0 || u > 1.0)
  {
    return false;
  }
  const Vec    qv = CrossV(s, e1);
  const double v = inv * DotV(direction, qv);
  if (v < 0.0 || u + v > 1.0)
  {
    return false;
  }
  const double t = inv * DotV(e2, qv);
  return t >= 0.0 && t <= 1.0;
}

double
PointSegment(const Vec & p, const Vec & a, const Vec & b)
{
  const Vec    ab = Sub(b, a);
  const double l = DotV(ab, ab);
  const double t = l > 0.0 ? std::min(1.0, std::max(0.0, DotV(Sub(p, a), ab) / l)) : 0.0;
  const Vec    d = Sub(p, Along(a, b, t));
  return std::sqrt(DotV(d, d));
}

double
PointTriangle(const Vec & p, const Vec & a, const Vec & b, const Vec & c)
{
  // Projection on the plane; inside (barycentric coordinates >= 0): the
  // height; otherwise the nearest edge.
  const Vec    n = CrossV(Sub(b, a), Sub(c, a));
  const double nn = DotV(n, n);
  const double h = DotV(Sub(p, a), n) / nn;
  const Vec    f = { p[0] - h * n[0], p[1] - h * n[1], p[2] - h * n[2] };
  const double wa = DotV(CrossV(Sub(b, f), Sub(c, f)), n);
  const double wb = DotV(CrossV(Sub(c, f), Sub(a, f)), n);
  const double wc = DotV(CrossV(Sub(a, f), Sub(b, f)), n);
  if (wa >= 0.0 && wb >= 0.0 && wc >= 0.0)
  {
    return std::abs(h) * std::sqrt(nn);
  }
  return std::min({ PointSegment(p, a, b), PointSegment(p, b, c), PointSegment(p, c, a) });
}

double
SegmentSegment(const Vec & p0, const Vec & p1, const Vec & q0, const Vec & q1)
{
  // The interior critical point of the two lines when both parameters fall
  // in [0, 1]; otherwise an end of one is a closest point.
  double best = std::min(
    { PointSegment(p0, q0, q1), PointSegment(p1, q0, q1), PointSegment(q0, p0, p1), PointSegment(q1, p0, p1) });
  const Vec    u = Sub(p1, p0);
  const Vec    v = Sub(q1, q0);
  const Vec    w = Sub(p0, q0);
  const double a = DotV(u, u), b = DotV(u, v), c = DotV(v, v), d = DotV(u, w), e = DotV(v, w);
  const double den = a * c - b * b;
  if (den > 1e-12 * a * c)
  {
    const double s = (b * e - c * d) / den;
    const double t = (a * e - b * d) / den;
    if (s >= 0.0 && s <= 1.0 && t >= 0.0 && t <= 1.0)
    {
      const Vec g = Sub(Along(p0, p1, s), Along(q0, q1, t));
      best = std::min(best, std::sqrt(DotV(g, g)));
    }
  }
  return best;
}

struct BruteForce
{
  std::size_t intersecting{ 0 };
  double      smallestDistance{ std::numeric_limits<double>::infinity() };
};

/** Every pair of triangles sharing no vertex: crossing edges, and the
 * smallest distance of the pairs whose boxes are within \a range. */
BruteForce
CheckAllPairs(const std::vector<double> & x, const std::vector<uint32_t> & triangles, double range)
{
  const std::size_t n = triangles.size() / 3;
  std::vector<Vec>  box(2 * n);
  auto              point = [&](uint32_t i) { return Vec{ x[3 * i], x[3 * i + 1], x[3 * i + 2] }; };
  for (std::size_t t = 0; t < n; ++t)
  {
    for (unsigned int k = 0; k < 3; ++k)
    {
      box[2 * t][k] =
        std::min({ x[3 * triangles[3 * t] + k], x[3 * triangles[3 * t + 1] + k], x[3 * triangles[3 * t + 2] + k] });
      box[2 * t + 1][k] =
        std::max({ x[3 * triangles[3 * t] + k], x[3 * triangles[3 * t + 1] + k], x[3 * triangles[3 * t + 2] + k] });
    }
  }
  BruteForce result;
  for (std::size_t t = 0; t < n; ++t)
  {
    for (std::size_t u = t + 1; u < n; ++u)
    {
      bool far = false;
      for (unsigned int k = 0; k < 3; ++k)
      {
        far = far || box[2 * t][k] > box[2 * u + 1][k] + range || box[2 * u][k] > box[2 * t + 1][k] + range;
      }
      const uint32_t * a = triangles.data() + 3 * t;
      const uint32_t * b = triangles.data() + 3 * u;
      bool             shared = false;
      for (unsigned int i = 0; i < 3; ++i)
      {
        for (unsigned int j = 0; j < 3; ++j)
        {
          shared = shared || a[i] == b[j];
        }
      }
      if (far || shared)
      {
        continue;
      }
      const Vec pa[3] = { point(a[0]), point(a[1]), point(a[2]) };
      const Vec pb[3] = { point(b[0]), point(b[1]), point(b[2]) };
      bool      hit = false;
      for (unsigned int k = 0; k < 3; ++k)
      {
        hit = hit || SegmentHitsTriangle(pa[k], pa[(k + 1) % 3], pb[0], pb[1], pb[2]) ||
              SegmentHitsTriangle(pb[k], pb[(k + 1) % 3], pa[0], pa[1], pa[2]);
      }
      double d = 0.0;
      if (hit)
      {
        ++result.intersecting;
      }
      else
      {
        d = std::numeric_limits<double>::infinity();
        for (unsigned int k = 0; k < 3; ++k)
        {
          d = std::min({ d, PointTriangle(pa[k], pb[0], pb[1], pb[2]), PointTriangle(pb[k], pa[0], pa[1], pa[2]) });
          for (unsigned int l = 0; l < 3; ++l)
          {
            d = std::min(d, SegmentSegment(pa[k], pa[(k + 1) % 3], pb[l], pb[(l + 1) % 3]));
          }
        }
      }
      result.smallestDistance = std::min(result.smallestDistance, d);
    }
  }
  return result;
}

/** Flat coordinates and triangles of a mesh. */
void
Flatten(const MeshType * mesh, std::vector<double> & x, std::vector<uint32_t> & triangles)
{
  x.clear();
  for (auto it = mesh->GetPoints()->Begin(); it != mesh->GetPoints()->End(); ++it)
  {
    for (unsigned int k = 0; k < 3; ++k)
    {
      x.push_back(it.Value()[k]);
    }
  }
  itk::SurfaceCollision::ExtractTriangles(mesh, triangles);
}

/** Two parallel squares of side 6 at z = 0 and z = gap, each a grid of
 * 13 x 13 points (edges 0.5) cut into 288 triangles, the upper one shifted
 * by (0.13, 0.07) in its plane: 3 doubles a point in x, 3 indices a triangle
 * in triangles; the upper sheet's points are the second half. */
void
TwoSheets(double gap, std::vector<double> & x, std::vector<uint32_t> & triangles, unsigned int m = 12)
{
  x.clear();
  triangles.clear();
  for (unsigned int sheet = 0; sheet < 2; ++sheet)
  {
    const auto base = static_cast<uint32_t>(x.size() / 3);
    for (unsigned int j = 0; j <= m; ++j)
    {
      for (unsigned int i = 0; i <= m; ++i)
      {
        x.push_back(0.5 * i + (sheet ? 0.13 : 0.0));
        x.push_back(0.5 * j + (sheet ? 0.07 : 0.0));
        x.push_back(sheet ? gap : 0.0);
      }
    }
    for (unsigned int j = 0; j < m; ++j)
    {
      for (unsigned int i = 0; i < m; ++i)
      {
        const uint32_t p = base + j * (m + 1) + i;
        triangles.insert(triangles.end(), { p, p + 1, p + m + 2, p, p + m + 2, p + m + 1 });
      }
    }
  }
}

/** TwoSheets() with the same corner of each sheet (point 12, the end of
 * the first row) pulled out by (1.5, -1.5): the one triangle at that corner
 * of each sheet is several times larger than the others (a large triangle
 * of the index, in no cell). */
void
TwoSheetsWithLargeCorners(double gap, std::vector<double> & x, std::vector<uint32_t> & triangles)
{
  TwoSheets(gap, x, triangles);
  const std::size_t n = x.size() / 3;
  for (const std::size_t corner : { std::size_t{ 12 }, n / 2 + 12 })
  {
    x[3 * corner] += 1.5;
    x[3 * corner + 1] -= 1.5;
  }
}
} // namespace

// ---------------------------------------------------------------------------
// Known configurations.

TEST(SurfaceCollision, OutwardFloatsEncloseTheDouble)
{
  // The branchless rounding of the displacement boxes: below <= m <= above
  // for every double, at most six units in the last place of the nearest
  // float (plus the absolute 1e-30 each side) apart for normal magnitudes;
  // zero, subnormals and values beyond the floats' range included.
  std::mt19937                           random(20261204);
  std::uniform_real_distribution<double> mantissa(-1.0, 1.0);
  std::uniform_int_distribution<int>     exponent(-140, 140);
  std::vector<double>                    values = {
                       0.0,  -0.0,  1e-300, -1e-300, 1e-45, -1e-45, 1.0, -1.0, 3.4028234663852886e38, -3.4028234663852886e38,
                       1e39, -1e39, 1e300,  -1e300
  };
  for (unsigned int i = 0; i < 100000; ++i)
  {
    values.push_back(std::ldexp(mantissa(random), exponent(random)));
  }
  for (const double m : values)
  {
    float below = 0.0f, above = 0.0f;
    itk::SurfaceCollisionDetail::OutwardFloats(m, m, below, above);
    ASSERT_LE(static_cast<double>(below), m) << m;
    ASSERT_GE(static_cast<double>(above), m) << m;
    if (std::abs(m) <= static_cast<double>(std::numeric_limits<float>::max()) &&
        std::abs(m) >= static_cast<double>(std::numeric_limits<float>::min()))
    {
      const auto  nearest = static_cast<float>(m);
      const float ulp = std::nextafter(std::abs(nearest), std::numeric_limits<float>::infinity()) - std::abs(nearest);
      ASSERT_LE(static_cast<double>(above) - static_cast<double>(below), 6.0 * ulp + 2.1e-30) << m;
    }
  }
}

TEST(SurfaceCollision, SpheresWithinFindsWhatTheScalarTestFinds)
{
  // The filter of the rebuild's candidate search against a plain loop, on
  // random spheres, with ranges that do not start or end on a multiple of 4.
  std::mt19937                          random(7);
  std::uniform_real_distribution<float> coordinate(-5.0f, 5.0f);
  std::uniform_real_distribution<float> radius(0.0f, 1.0f);
  const uint32_t                        count = 1003;
  std::vector<float>                    x(count + 4), y(count + 4), z(count + 4), r(count + 4);
  for (uint32_t j = 0; j < count; ++j)
  {
    x[j] = coordinate(random);
    y[j] = coordinate(random);
    z[j] = coordinate(random);
    r[j] = radius(random);
  }
  std::vector<uint32_t> hits(count + 4);
  std::size_t           total = 0;
  for (uint32_t first = 0; first < 40; first += 7)
  {
    for (const uint32_t last : { count, count - 1, count - 2, count - 3, first, first + 1 })
    {
      const float              px = coordinate(random), py = coordinate(random), pz = coordinate(random);
      const float              reach = 2.0f * radius(random);
      const itk::SizeValueType found = itk::SurfaceCollisionDetail::SpheresWithin(
        x.data(), y.data(), z.data(), r.data(), first, last, px, py, pz, reach, hits.data());
      // In double: found when clearly inside, not found when clearly
      // outside (the float sums may round either way at the boundary).
      std::vector<char> isHit(count, 0);
      for (itk::SizeValueType h = 0; h < found; ++h)
      {
        ASSERT_TRUE(hits[h] >= first && hits[h] < last && (h == 0 || hits[h] > hits[h - 1])) << hits[h];
        isHit[hits[h]] = 1;
      }
      for (uint32_t j = first; j < last; ++j)
      {
        const double dx = double{ x[j] } - px, dy = double{ y[j] } - py, dz = double{ z[j] } - pz;
        const double limit = double{ r[j] } + reach;
        const double sum = dx * dx + dy * dy + dz * dz;
        if (sum < limit * limit * (1.0 - 1e-5))
        {
          ASSERT_TRUE(isHit[j]) << "range " << first << " to " << last << ", sphere " << j;
        }
        if (sum > limit * limit * (1.0 + 1e-5))
        {
          ASSERT_FALSE(isHit[j]) << "range " << first << " to " << last << ", sphere " << j;
        }
      }
      total += found;
    }
  }
  EXPECT_GT(total, 100u) << "the spheres were near enough to be found";
}

TEST(SurfaceCollision, ParallelTrianglesAtDistanceDGiveDExactly)
{
  const Triangle a = { { 0, 0, 0 }, { 4, 0, 0 }, { 0, 4, 0 } };
  for (const double d : { 0.25, 0.1, 1.0 / 3.0, 7.5 })
  {
    // Overlapping in projection: the closest points are interior to a face.
    const Triangle b = { { 0.5, 0.5, d }, { 2.5, 0.5, d }, { 0.5, 2.5, d } };
    EXPECT_EQ(Distance(a, b), d);
    EXPECT_FALSE(Intersect(a, b));
    // The same plane, reversed orientation, shifted: still d.
    const Triangle c = { { 1, 1, -d }, { 1, 3, -d }, { 3, 1, -d } };
    EXPECT_EQ(Distance(a, c), d);
  }
}

TEST(SurfaceCollision, EdgeThroughFaceIntersects)
{
  const Triangle a = { { 0, 0, 0 }, { 4, 0, 0 }, { 0, 4, 0 } };
  // b pierces a: one vertex below, two above, crossing inside a.
  const Triangle b = { { 1, 1, -1 }, { 1, 1, 1 }, { 1.5, 1.2, 1 } };
  EXPECT_TRUE(Intersect(a, b));
  EXPECT_EQ(Distance(a, b), 0.0);
  // The same shifted beyond a's hypotenuse x + y = 4: no contact, distance
  // from the edge (1.5+s, 1.2+s) ... the nearest vertex-edge pair.
  const Triangle c = { { 3, 3, -1 }, { 3, 3, 1 }, { 3.5, 3.2, 1 } };
  EXPECT_FALSE(Intersect(a, c));
  // Closest: the segment x = y = 3 to the edge x + y = 4 at (2, 2, 0): sqrt 2.
  EXPECT_NEAR(Distance(a, c), std::sqrt(2.0), 1e-15);
  // Two triangles linked like chain links: each pierces the other.
  const Triangle d = { { -1, 0, 0 }, { 1, 0, 0 }, { 0, 2, 0 } };
  const Triangle e = { { 0, 1, -1 }, { 0, 1, 1 }, { 0, -1, 0.2 } };
  EXPECT_TRUE(Intersect(d, e));
}

TEST(SurfaceCollision, TouchingTrianglesIntersect)
{
  const Triangle a = { { 0, 0, 0 }, { 4, 0, 0 }, { 0, 4, 0 } };
  // A vertex of b on a's face.
  const Triangle b = { { 1, 1, 0 }, { 1, 1, 2 }, { 2, 1, 2 } };
  EXPECT_TRUE(Intersect(a, b));
  EXPECT_EQ(Distance(a, b), 0.0);
  // An edge of b on a's edge (collinear overlap), b out of a's plane.
  const Triangle c = { { 1, 0, 0 }, { 3, 0, 0 }, { 2, -1, 1 } };
  EXPECT_TRUE(Intersect(a, c));
  // Vertex to vertex.
  const Triangle e = { { 4, 0, 0 }, { 5, 1, 1 }, { 5, -1, 1 } };
  EXPECT_TRUE(Intersect(a, e));
  // Lifted by 1e-9: apart, and the distance says so.
  const Triangle f = { { 1, 1, 1e-9 }, { 1, 1, 2 }, { 2, 1, 2 } };
  EXPECT_FALSE(Intersect(a, f));
  EXPECT_EQ(Distance(a, f), 1e-9);
}

TEST(SurfaceCollision, CoplanarTriangles)
{
  const Triangle a = { { 0, 0, 0 }, { 4, 0, 0 }, { 0, 4, 0 } };
  // Overlapping edges.
  const Triangle b = { { 1, 1, 0 }, { 5, 1, 0 }, { 1, 5, 0 } };
  EXPECT_TRUE(Intersect(a, b));
  EXPECT_EQ(Distance(a, b), 0.0);
  // b inside a, no edge crossing.
  const Triangle c = { { 0.5, 0.5, 0 }, { 1.5, 0.5, 0 }, { 0.5, 1.5, 0 } };
  EXPECT_TRUE(Intersect(a, c));
  EXPECT_TRUE(Intersect(c, a));
  // Apart in the plane by 1 along x (vertex (5, 0) to a's vertex (4, 0)).
  const Triangle e = { { 5, 0, 0 }, { 7, 0, 0 }, { 5, 2, 0 } };
  EXPECT_FALSE(Intersect(a, e));
  EXPECT_EQ(Distance(a, e), 1.0);
  // Across the hypotenuse: (3, 3) to the line x + y = 4 is sqrt(2).
  const Triangle g = { { 3, 3, 0 }, { 5, 3, 0 }, { 3, 5, 0 } };
  EXPECT_FALSE(Intersect(a, g));
  EXPECT_NEAR(Distance(a, g), std::sqrt(2.0), 1e-15);
}

TEST(SurfaceCollision, SkewEdgesGiveTheLineDistance)
{
  // Edges x in [-1, 1] at (y, z) = (0, 0) and y in [-1, 1] at x = 0, z = h:
  // the closest points are the edges' midpoints, h apart.
  const double   h = 0.375;
  const Triangle a = { { -1, 0, 0 }, { 1, 0, 0 }, { 0, 0, -2 } };
  const Triangle b = { { 0, -1, h }, { 0, 1, h }, { 0, 0, h + 2 } };
  EXPECT_FALSE(Intersect(a, b));
  EXPECT_EQ(Distance(a, b), h);
}

TEST(SurfaceCollision, NearlyCoplanarTrianglesOfAFlatPatchDoNotIntersect)
{
  // Two triangles of edmodel's refined brain mesh (ch2bet, --init-sphere
  // 0,-18,10,40): children of one flat patch that no step had moved, 1e-17
  // out of each other's planes and some 0.1 mm apart in them. The plain
  // double determinants called them crossing (the filter then refused the
  // next level's input); exact signs do not.
  const Triangle a = { { 0.53191228781025468, 38.184761268182463, -9.2977485889955709 },
                       { 0.52962394388423373, 38.287848613370436, -8.9297869451913314 },
                       { 0.56356014829611922, 38.411527656823552, -9.7360562562974078 } };
  const Triangle b = { { 0.52733559995821278, 38.390935958558408, -8.561825301387092 },
                       { 0.52504725603219182, 38.494023303746381, -8.1938636575828525 },
                       { 0.55898346044407732, 38.617702347199497, -9.0001329686889289 } };
  EXPECT_FALSE(Intersect(a, b));
  EXPECT_GT(Distance(a, b), 0.05);

  // A flat patch in a tilted plane (6 x 6 squares, 72 triangles), split
  // twice at the midpoints of its edges (each triangle into four, as
  // edmodel refines): its triangles meet only at shared vertices and edges,
  // so no pair sharing no vertex intersects (the plain determinants found 1
  // and 5 pairs after the first and second split).
  const double          o[3] = { 0.52533177940643472, 39.766135981018408, -13.271738695729825 };
  const double          u[3] = { 0.0032902541, -0.7906873565, 1.9869950767 };
  const double          v[3] = { 0.0665859750, -0.3371546, 1.1103799 };
  const unsigned int    m = 6;
  std::vector<double>   x;
  std::vector<uint32_t> triangles;
  for (unsigned int j = 0; j <= m; ++j)
  {
    for (unsigned int i = 0; i <= m; ++i)
    {
      for (unsigned int k = 0; k < 3; ++k)
      {
        x.push_back(o[k] + 0.37 * i * u[k] + 0.41 * j * v[k]);
      }
    }
  }
  for (unsigned int j = 0; j < m; ++j)
  {
    for (unsigned int i = 0; i < m; ++i)
    {
      const uint32_t p = j * (m + 1) + i;
      triangles.insert(triangles.end(), { p, p + 1, p + m + 2, p, p + m + 2, p + m + 1 });
    }
  }
  for (unsigned int level = 0; level < 3; ++level)
  {
    EXPECT_EQ(itk::SurfaceCollision::CountSelfIntersections(x.data(), triangles.data(), triangles.size() / 3), 0u)
      << "after " << level << " splits";
    std::map<std::pair<uint32_t, uint32_t>, uint32_t> midpoints;
    const auto                                        midpoint = [&](uint32_t p, uint32_t q) {
      const auto key = std::make_pair(std::min(p, q), std::max(p, q));
      const auto found = midpoints.find(key);
      if (found != midpoints.end())
      {
        return found->second;
      }
      for (unsigned int k = 0; k < 3; ++k)
      {
        x.push_back(0.5 * (x[3 * p + k] + x[3 * q + k]));
      }
      const auto id = static_cast<uint32_t>(x.size() / 3 - 1);
      midpoints.emplace(key, id);
      return id;
    };
    std::vector<uint32_t> split;
    for (std::size_t t = 0; t < triangles.size() / 3; ++t)
    {
      const uint32_t p = triangles[3 * t], q = triangles[3 * t + 1], r = triangles[3 * t + 2];
      const uint32_t pq = midpoint(p, q), qr = midpoint(q, r), rp = midpoint(r, p);
      split.insert(split.end(), { p, pq, rp, pq, q, qr, rp, qr, r, pq, qr, rp });
    }
    triangles.swap(split);
  }
}

TEST(SurfaceCollision, TrianglesSharingAVertexDoNotFoldThroughEachOther)
{
  // Two triangles of one fan, sharing only the vertex v = 0: a in the plane
  // z = 0, b above it. The step moves one far vertex of b below the plane,
  // so that b would cut through a along a segment from v (b's far edge
  // crossing a at (0.35, 0.35, 0)). Such pairs are not tested as
  // "triangles sharing no vertex", but they must not pass through each
  // other: Constrain() reduces the step until b's far edge stays clear of a.
  std::vector<double>         x = { 0, 0, 0, 1, 0, 0, 0, 1, 0, 0.5, 0.2, 1, 0.2, 0.5, 1 };
  const std::vector<uint32_t> triangles = { 0, 1, 2, 0, 3, 4 };
  std::vector<double>         y = x;
  y[3 * 3 + 2] = -1.0;
  const Vec  v0{ 0, 0, 0 }, a1{ 1, 0, 0 }, a2{ 0, 1, 0 };
  const auto farEdgeHitsA = [&](const std::vector<double> & p) {
    return SegmentHitsTriangle(Vec{ p[9], p[10], p[11] }, Vec{ p[12], p[13], p[14] }, v0, a1, a2);
  };
  ASSERT_FALSE(farEdgeHitsA(x));
  ASSERT_TRUE(farEdgeHitsA(y)) << "unconstrained, b cuts through a";

  itk::SurfaceCollision collision;
  collision.SetSurface(5, triangles.data(), 2);
  const auto result = collision.Constrain(x.data(), y.data(), 0.0, nullptr, 1);
  EXPECT_GT(result.violations, 0u);
  EXPECT_FALSE(farEdgeHitsA(y)) << "b's far vertex at z = " << y[11];
  // The known answer: b's far edge crosses the plane z = 0 inside a for
  // every lowering of the vertex below z = 0, so the halvings go on until
  // its displacement is a quarter (z = 0.5), then zero: z = 1 - 2 / 4 = 0.5
  // after two halvings leaves both far vertices above the plane.
  EXPECT_EQ(y[11], 0.5);
  for (unsigned int k = 0; k < 15; ++k)
  {
    if (k != 11)
    {
      EXPECT_EQ(y[k], x[k]) << k;
    }
  }
  const double * pa[3] = { y.data(), y.data() + 3, y.data() + 6 };
  const double * pb[3] = { y.data(), y.data() + 9, y.data() + 12 };
  EXPECT_GT(itk::SurfaceCollisionDetail::SharedVertexGap(pa, 0, pb, 0), 0.0);

  // A step that lifts b without folding it is left alone.
  std::vector<double> lifted = x;
  lifted[3 * 3 + 2] = 2.0;
  const auto kept = collision.Constrain(x.data(), lifted.data(), 0.0, nullptr, 1);
  EXPECT_EQ(kept.violations, 0u);
  EXPECT_EQ(lifted[11], 2.0);
}

TEST(SurfaceCollision, ACarriedSharedGapLosesThePairsMotion)
{
  // Two triangles of one fan sharing only v = 0: a in the plane z = 0, b
  // tilted above it with its far edge 0.2 above a's interior (their gap
  // 0.2), and a triangle far away (congruent with a) that moves only to
  // make the index rebuild. Step 1 lowers b's far edge by 0.1 while the far
  // triangle stretches: the index is rebuilt at the proposed positions and
  // the pair's bound is carried over (computed at the first rebuild, less
  // the pair's motion: about 0.1). Step 2 lowers one end of b's far edge
  // by 0.15, a relative motion that keeps the index, so that the edge
  // crosses a at about (0.62, 0.33, 0). Only the carried
  // bound decides whether the pair is tested: one that kept the bound of
  // the first rebuild (0.2) calls the pair clear and lets b fold through a.
  std::vector<double> x = {
    0, 0, 0, 1, 0, 0, 0, 1, 0, 0.9, 0.05, 0.2, 0.05, 0.9, 0.2, 100, 0, 0, 101, 0, 0, 100, 1, 0
  };
  const std::vector<uint32_t> triangles = { 0, 1, 2, 0, 3, 4, 5, 6, 7 };
  const Vec                   v0{ 0, 0, 0 }, a1{ 1, 0, 0 }, a2{ 0, 1, 0 };
  const auto                  farEdgeHitsA = [&](const std::vector<double> & p) {
    return SegmentHitsTriangle(Vec{ p[9], p[10], p[11] }, Vec{ p[12], p[13], p[14] }, v0, a1, a2);
  };
  itk::SurfaceCollision collision;
  collision.SetSurface(8, triangles.data(), 3);
  std::vector<double> y = x;
  ASSERT_TRUE(collision.Constrain(x.data(), y.data(), 0.0, nullptr, 1).rebuilt);
  EXPECT_EQ(collision.GetNumberOfComputedSharedGaps(), 1u);
  EXPECT_EQ(collision.GetNumberOfLargeTriangles(), 0u);

  y[11] -= 0.1;
  y[14] -= 0.1;
  y[3 * 6] += 30.0;
  const auto first = collision.Constrain(x.data(), y.data(), 0.0, nullptr, 1);
  ASSERT_TRUE(first.rebuilt) << "the far triangle's stretch exceeds the bounds";
  EXPECT_EQ(first.violations, 0u);
  EXPECT_EQ(collision.GetNumberOfComputedSharedGaps(), 0u) << "the pair's bound carried over";

  x = y;
  y[11] -= 0.15;
  ASSERT_TRUE(farEdgeHitsA(y)) << "unconstrained, b's far edge crosses a";
  const auto second = collision.Constrain(x.data(), y.data(), 0.0, nullptr, 1);
  EXPECT_FALSE(second.rebuilt) << "the carried bound decides";
  EXPECT_GT(second.violations, 0u);
  EXPECT_FALSE(farEdgeHitsA(y)) << "b's far edge at z = " << y[11];
  const double * pa[3] = { y.data(), y.data() + 3, y.data() + 6 };
  const double * pb[3] = { y.data(), y.data() + 9, y.data() + 12 };
  EXPECT_GT(itk::SurfaceCollisionDetail::SharedVertexGap(pa, 0, pb, 0), 0.0);
  // One halving: b's far edge at z = 0.1 - 0.075.
  EXPECT_DOUBLE_EQ(y[11], 0.025);
}

TEST(SurfaceCollision, DistanceAgreesWithTheIndependentCode)
{
  // Random pairs: the component's distance and intersection test against
  // the brute-force helpers of this file.
  std::mt19937                           random(7);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  unsigned int                           crossings = 0;
  for (unsigned int trial = 0; trial < 20000; ++trial)
  {
    Triangle a(3), b(3);
    for (unsigned int k = 0; k < 3; ++k)
    {
      for (unsigned int c = 0; c < 3; ++c)
      {
        a[k][c] = uniform(random);
        b[k][c] = uniform(random) + 0.5;
      }
    }
    bool hit = false;
    for (unsigned int k = 0; k < 3; ++k)
    {
      hit = hit || SegmentHitsTriangle(a[k], a[(k + 1) % 3], b[0], b[1], b[2]) ||
            SegmentHitsTriangle(b[k], b[(k + 1) % 3], a[0], a[1], a[2]);
    }
    ASSERT_EQ(Intersect(a, b), hit) << "trial " << trial;
    crossings += hit;
    if (!hit)
    {
      double d = std::numeric_limits<double>::infinity();
      for (unsigned int k = 0; k < 3; ++k)
      {
        d = std::min({ d, PointTriangle(a[k], b[0], b[1], b[2]), PointTriangle(b[k], a[0], a[1], a[2]) });
        for (unsigned int l = 0; l < 3; ++l)
        {
          d = std::min(d, SegmentSegment(a[k], a[(k + 1) % 3], b[l], b[(l + 1) % 3]));
        }
      }
      ASSERT_NEAR(Distance(a, b), d, 1e-12) << "trial " << trial;
    }
  }
  EXPECT_GT(crossings, 1000u) << "both outcomes are exercised";
  EXPECT_LT(crossings, 19000u);
}

// ---------------------------------------------------------------------------
// The index.

TEST(SurfaceCollision, CountsTheIntersectionsOfTwoOverlappingSpheres)
{
  // Two spheres of radius 5, centres about 6 apart: they cross along a
  // circle. (Off the axes: with centres (0, 0, 0) and (6, 0, 0) the meshes
  // are mirror images and some pairs touch exactly along edges, where the
  // outcome of any floating-point test is the rounding's.)
  MeshType::PointType c1, c2;
  c1.Fill(0.0);
  c2[0] = 6.0;
  c2[1] = 0.23;
  c2[2] = 0.17;
  const auto            one = itk::MakeSphereMesh<MeshType>(c1, 5.0, 3);
  const auto            two = itk::MakeSphereMesh<MeshType>(c2, 5.0, 3);
  std::vector<double>   x, x2;
  std::vector<uint32_t> t, t2;
  Flatten(one, x, t);
  Flatten(two, x2, t2);
  EXPECT_EQ(itk::SurfaceCollision::CountSelfIntersections(x.data(), t.data(), t.size() / 3), 0u);
  EXPECT_EQ(itk::SurfaceCollision::CountSelfIntersections(one.GetPointer()), 0u);
  const auto offset = static_cast<uint32_t>(x.size() / 3);
  x.insert(x.end(), x2.begin(), x2.end());
  for (const uint32_t v : t2)
  {
    t.push_back(v + offset);
  }
  std::pair<itk::SizeValueType, itk::SizeValueType> first;
  const itk::SizeValueType                          count =
    itk::SurfaceCollision::CountSelfIntersections(x.data(), t.data(), t.size() / 3, &first);
  const BruteForce all = CheckAllPairs(x, t, 0.0);
  EXPECT_GT(count, 20u);
  EXPECT_EQ(count, all.intersecting) << "the grid finds every pair the all-pairs test finds";
  EXPECT_LT(first.first, first.second);
  EXPECT_GE(first.second, t2.size() / 3) << "one triangle of each sphere";
  // The same count and first pair from parallel blocks (the two spheres are
  // closed but not star-shaped: the grid is searched).
  {
    auto threader = itk::MultiThreaderBase::New();
    threader->SetMaximumNumberOfThreads(2);
    std::pair<itk::SizeValueType, itk::SizeValueType> parallelFirst;
    EXPECT_EQ(
      itk::SurfaceCollision::CountSelfIntersections(x.data(), t.data(), t.size() / 3, &parallelFirst, threader, 8),
      count);
    EXPECT_EQ(parallelFirst, first);
  }
  // Apart (centres more than 10.5 apart): none.
  for (std::size_t i = offset; i < x.size() / 3; ++i)
  {
    x[3 * i] += 4.5;
  }
  EXPECT_EQ(itk::SurfaceCollision::CountSelfIntersections(x.data(), t.data(), t.size() / 3), 0u);
}

TEST(SurfaceCollision, ConstrainStopsFrontsPushedThroughEachOther)
{
  // Two parallel sheets 2 apart (triangulated squares), each pushed 1.6 toward
  // the other in one step, with a few vertices pushed further: without the
  // constraint they cross; constrained, none intersects and no pair is
  // closer than d, nor did the sheets move where they are clear.
  std::vector<double>   x;
  std::vector<uint32_t> triangles;
  TwoSheets(2.0, x, triangles);
  const std::size_t   n = x.size() / 3;
  std::vector<double> y = x;
  for (std::size_t i = 0; i < n; ++i)
  {
    const bool   upper = i >= n / 2;
    const double px = x[3 * i] - 3.0, py = x[3 * i + 1] - 3.0;
    // A bump: up to 1.2 toward the other sheet at the centre, 0 at the rim.
    const double push = 1.2 * std::max(0.0, 1.0 - (px * px + py * py) / 6.0);
    y[3 * i + 2] += upper ? -push : push;
    y[3 * i] += 0.01; // everything moves a little
  }
  EXPECT_GT(CheckAllPairs(y, triangles, 0.0).intersecting, 0u) << "unconstrained, the fronts cross";

  const double          d = 0.3;
  itk::SurfaceCollision collision;
  collision.SetSurface(n, triangles.data(), triangles.size() / 3);
  const auto result = collision.Constrain(x.data(), y.data(), d, nullptr, 1);
  EXPECT_TRUE(result.rebuilt);
  EXPECT_GT(result.violations, 0u);
  EXPECT_GT(result.constrained, 0u);
  EXPECT_EQ(result.constrained, collision.GetConstrainedPoints().size());
  const BruteForce after = CheckAllPairs(y, triangles, d);
  EXPECT_EQ(after.intersecting, 0u);
  EXPECT_GE(after.smallestDistance, d);
  // Points away from the bump (push 0) kept their displacement unless the
  // constraint reduced it: the rim moved by exactly 0.01 along x.
  EXPECT_EQ(y[0], x[0] + 0.01);
  EXPECT_EQ(y[2], x[2]);

  // A second step from the constrained state: the same push again, with the
  // index kept (nothing left its skin): still clear.
  std::vector<double> x2 = y;
  std::vector<double> y2 = y;
  for (std::size_t i = 0; i < n; ++i)
  {
    y2[3 * i + 2] += (i >= n / 2) ? -0.2 : 0.2;
  }
  collision.Constrain(x2.data(), y2.data(), d, nullptr, 1);
  const BruteForce second = CheckAllPairs(y2, triangles, d);
  EXPECT_EQ(second.intersecting, 0u);
  EXPECT_GE(second.smallestDistance, d);
}

namespace
{
/** A sphere of radius 5 (resolution 3: 258 points) off the origin, flat. */
void
StarSphere(std::vector<double> & x, std::vector<uint32_t> & triangles, double radius = 5.0)
{
  MeshType::PointType centre;
  centre[0] = 1.3;
  centre[1] = -0.7;
  centre[2] = 2.1;
  Flatten(itk::MakeSphereMesh<MeshType>(centre, radius, 3), x, triangles);
}

/** y = x with every point moved along its direction from the sphere's
 * centre by \a grow times a smooth factor in [0.5, 1.5] that changes with
 * \a step: a star-shaped surface stays star-shaped. */
std::vector<double>
Inflate(const std::vector<double> & x, double grow, unsigned int step)
{
  std::vector<double> y = x;
  for (std::size_t i = 0; i < x.size() / 3; ++i)
  {
    const double d[3] = { x[3 * i] - 1.3, x[3 * i + 1] + 0.7, x[3 * i + 2] - 2.1 };
    const double r = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
    const double f = 1.0 + 0.5 * std::sin(0.7 * d[0] + 0.3 * step) * std::cos(0.5 * d[2]);
    for (unsigned int k = 0; k < 3; ++k)
    {
      y[3 * i + k] += grow * f * d[k] / r;
    }
  }
  return y;
}

/** StarSphere()'s points with point 0 pushed through the sphere, to 1.5
 * times its radius on the other side: intersecting. */
std::vector<double>
PushedThrough(const std::vector<double> & x)
{
  std::vector<double> y = x;
  const double        centre[3] = { 1.3, -0.7, 2.1 };
  for (unsigned int k = 0; k < 3; ++k)
  {
    y[k] = centre[k] - 1.5 * (x[k] - centre[k]);
  }
  return y;
}

/** StarSphere()'s points with point 0 pulled sideways until one of its
 * triangles turns its back to the centre, without intersecting: a fold. */
std::vector<double>
Leaning(const std::vector<double> & x)
{
  std::vector<double> y = x;
  y[0] += 4.0;
  y[1] += 4.0;
  return y;
}
} // namespace

TEST(SurfaceCollision, TheStarShapedCertificateKnowsItsSurfaces)
{
  std::vector<double>   x;
  std::vector<uint32_t> triangles;
  StarSphere(x, triangles);
  const std::size_t     n = x.size() / 3;
  itk::SurfaceCollision collision;
  collision.SetSurface(n, triangles.data(), triangles.size() / 3);
  EXPECT_TRUE(collision.IsClosedSurface());
  EXPECT_TRUE(collision.IsStarShaped(x.data()));
  // Bumped but star-shaped; the same with the triangles turned inward.
  const std::vector<double> bumped = Inflate(x, 2.0, 0);
  EXPECT_TRUE(collision.IsStarShaped(bumped.data()));
  std::vector<uint32_t> inward = triangles;
  for (std::size_t t = 0; t < inward.size() / 3; ++t)
  {
    std::swap(inward[3 * t + 1], inward[3 * t + 2]);
  }
  itk::SurfaceCollision turned;
  turned.SetSurface(n, inward.data(), inward.size() / 3);
  EXPECT_TRUE(turned.IsStarShaped(bumped.data()));

  // Point 0 pushed through the sphere: intersecting, not certified.
  const std::vector<double> folded = PushedThrough(x);
  ASSERT_GT(CheckAllPairs(folded, triangles, 0.0).intersecting, 0u);
  EXPECT_FALSE(collision.IsStarShaped(folded.data()));
  // Point 0 pulled sideways until one of its triangles turns its back to
  // the centre, without intersecting: not star-shaped from the centroid,
  // not certified (the index decides).
  EXPECT_FALSE(collision.IsStarShaped(Leaning(x).data()));

  // Two spheres, one inside the other, both turned outward: every triangle
  // faces away from the centre, but a ray crosses two: not certified.
  std::vector<double>   inner;
  std::vector<uint32_t> innerTriangles;
  StarSphere(inner, innerTriangles, 3.0);
  std::vector<double>   nested = x;
  std::vector<uint32_t> nestedTriangles = triangles;
  nested.insert(nested.end(), inner.begin(), inner.end());
  for (const uint32_t v : innerTriangles)
  {
    nestedTriangles.push_back(static_cast<uint32_t>(v + n));
  }
  itk::SurfaceCollision two;
  two.SetSurface(nested.size() / 3, nestedTriangles.data(), nestedTriangles.size() / 3);
  EXPECT_TRUE(two.IsClosedSurface());
  EXPECT_FALSE(two.IsStarShaped(nested.data()));

  // Open surfaces, and a closed one with a triangle turned over, are not
  // closed in the certificate's sense.
  std::vector<double>   sheets;
  std::vector<uint32_t> sheetTriangles;
  TwoSheets(1.0, sheets, sheetTriangles);
  itk::SurfaceCollision open;
  open.SetSurface(sheets.size() / 3, sheetTriangles.data(), sheetTriangles.size() / 3);
  EXPECT_FALSE(open.IsClosedSurface());
  EXPECT_FALSE(open.IsStarShaped(sheets.data()));
  std::vector<uint32_t> oneTurned = triangles;
  std::swap(oneTurned[1], oneTurned[2]);
  itk::SurfaceCollision mixed;
  mixed.SetSurface(n, oneTurned.data(), oneTurned.size() / 3);
  EXPECT_FALSE(mixed.IsClosedSurface());
  EXPECT_FALSE(mixed.IsStarShaped(x.data()));
}

namespace
{
/** Pairs of triangles sharing exactly one point that meet elsewhere (a fan
 * folded into itself): the edge opposite the shared point of one crosses
 * the other triangle. */
std::size_t
CountFoldedFans(const std::vector<double> & x, const std::vector<uint32_t> & triangles)
{
  const std::size_t n = triangles.size() / 3;
  const auto        point = [&](uint32_t i) { return Vec{ x[3 * i], x[3 * i + 1], x[3 * i + 2] }; };
  std::size_t       folded = 0;
  for (std::size_t t = 0; t < n; ++t)
  {
    for (std::size_t u = t + 1; u < n; ++u)
    {
      const uint32_t * a = triangles.data() + 3 * t;
      const uint32_t * b = triangles.data() + 3 * u;
      unsigned int     shared = 0;
      unsigned int     i = 0;
      unsigned int     j = 0;
      for (unsigned int p = 0; p < 3; ++p)
      {
        for (unsigned int q = 0; q < 3; ++q)
        {
          if (a[p] == b[q])
          {
            ++shared;
            i = p;
            j = q;
          }
        }
      }
      if (shared == 1 &&
          (SegmentHitsTriangle(point(a[(i + 1) % 3]), point(a[(i + 2) % 3]), point(b[0]), point(b[1]), point(b[2])) ||
           SegmentHitsTriangle(point(b[(j + 1) % 3]), point(b[(j + 2) % 3]), point(a[0]), point(a[1]), point(a[2]))))
      {
        ++folded;
      }
    }
  }
  return folded;
}

/** u x v and u . v in long double, for the certificates' bounds computed
 * again. */
void
LongCross(const long double * u, const long double * v, long double * w)
{
  w[0] = u[1] * v[2] - u[2] * v[1];
  w[1] = u[2] * v[0] - u[0] * v[2];
  w[2] = u[0] * v[1] - u[1] * v[0];
}
long double
LongDot(const long double * u, const long double * v)
{
  return u[0] * v[0] + u[1] * v[1] + u[2] * v[2];
}
} // namespace

TEST(SurfaceCollision, TheCertificateCarriesToPositionsWithinItsMargin)
{
  // A certificate without folds carries a margin: positions with every
  // point within it of the certified ones are star-shaped from the same
  // centre, and are accepted by a pass over the points.
  std::vector<double>   x;
  std::vector<uint32_t> triangles;
  StarSphere(x, triangles);
  const std::size_t     n = x.size() / 3;
  const std::size_t     numberOfTriangles = triangles.size() / 3;
  itk::SurfaceCollision collision;
  collision.SetSurface(n, triangles.data(), numberOfTriangles);
  std::vector<double> y = x;
  EXPECT_EQ(collision.Constrain(x.data(), y.data(), 0.0, nullptr, 1).constrained, 0u);
  EXPECT_EQ(collision.GetTotalNumberOfCertifiedSteps(), 1u);
  EXPECT_EQ(collision.GetTotalNumberOfCarriedCertificates(), 0u);
  const double margin = collision.GetCarriedMargin();

  // The centre of the certificate: the centroid of the points.
  double centre[3] = { 0.0, 0.0, 0.0 };
  for (std::size_t i = 0; i < n; ++i)
  {
    for (unsigned int d = 0; d < 3; ++d)
    {
      centre[d] += x[3 * i + d] / static_cast<double>(n);
    }
  }
  // Bounds: above, the least distance from the centre to a triangle's plane
  // (moving a triangle's points that far toward the centre puts the centre
  // on it); below, not vanishing on this regular sphere (about a fifth of
  // its edge length, 1.1, here). Twice the margin fails the test of the
  // steepest motions below.
  const auto sub = [](const double * p, const double * q, long double * r) {
    for (unsigned int d = 0; d < 3; ++d)
    {
      r[d] = static_cast<long double>(p[d]) - static_cast<long double>(q[d]);
    }
  };
  const auto  cross = LongCross;
  const auto  dot = LongDot;
  long double nearestPlane = std::numeric_limits<long double>::infinity();
  for (std::size_t t = 0; t < numberOfTriangles; ++t)
  {
    long double a[3], b[3], c[3], ab[3], ac[3], normal[3];
    sub(&x[3 * triangles[3 * t]], centre, a);
    sub(&x[3 * triangles[3 * t + 1]], centre, b);
    sub(&x[3 * triangles[3 * t + 2]], centre, c);
    for (unsigned int d = 0; d < 3; ++d)
    {
      ab[d] = b[d] - a[d];
      ac[d] = c[d] - a[d];
    }
    cross(ab, ac, normal);
    nearestPlane = std::min(nearestPlane, std::abs(dot(a, normal)) / std::sqrt(dot(normal, normal)));
  }
  EXPECT_LT(margin, static_cast<double>(nearestPlane));
  EXPECT_GT(margin, 0.15);
  std::cout << "margin " << margin << ", nearest plane " << static_cast<double>(nearestPlane) << std::endl;

  // For each triangle, its points moved by the margin in the directions
  // that shrink its orientation determinant fastest (against the gradient:
  // B x C for A, ...): every orientation keeps its sign (long double).
  for (std::size_t t = 0; t < numberOfTriangles; ++t)
  {
    long double p[3][3];
    for (unsigned int k = 0; k < 3; ++k)
    {
      sub(&x[3 * triangles[3 * t + k]], centre, p[k]);
    }
    long double gradient[3][3];
    cross(p[1], p[2], gradient[0]);
    cross(p[2], p[0], gradient[1]);
    cross(p[0], p[1], gradient[2]);
    const long double before = dot(p[0], gradient[0]);
    for (unsigned int k = 0; k < 3; ++k)
    {
      const long double length = std::sqrt(dot(gradient[k], gradient[k]));
      for (unsigned int d = 0; d < 3; ++d)
      {
        p[k][d] -= (before > 0 ? 1 : -1) * static_cast<long double>(margin) * gradient[k][d] / length;
      }
    }
    long double bc[3];
    cross(p[1], p[2], bc);
    ASSERT_GT(before * dot(p[0], bc), 0.0L) << "triangle " << t;
  }

  // Random displacements of length 0.999 margin: certified by the margin
  // (no new certificate), and star-shaped, free of intersecting pairs, as
  // the exact certificate and the test of all pairs find.
  std::mt19937                     random(7);
  std::normal_distribution<double> normal(0.0, 1.0);
  for (int trial = 0; trial < 20; ++trial)
  {
    y = x;
    for (std::size_t i = 0; i < n; ++i)
    {
      double       v[3] = { normal(random), normal(random), normal(random) };
      const double length = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
      for (unsigned int d = 0; d < 3; ++d)
      {
        y[3 * i + d] += 0.999 * margin * v[d] / length;
      }
    }
    const std::vector<double> proposed = y;
    EXPECT_EQ(collision.Constrain(x.data(), y.data(), 0.0, nullptr, 1).constrained, 0u);
    EXPECT_EQ(y, proposed);
    EXPECT_EQ(collision.GetTotalNumberOfCarriedCertificates(), static_cast<std::size_t>(trial + 1));
    itk::SurfaceCollision fresh;
    fresh.SetSurface(n, triangles.data(), numberOfTriangles);
    EXPECT_TRUE(fresh.IsStarShaped(y.data()));
    EXPECT_EQ(CheckAllPairs(y, triangles, 0.0).intersecting, 0u);
  }
  // One point moved by twice the margin: its triangles followed from the
  // certified positions (CarriedTo()), no certificate.
  y = x;
  y[0] += 2.0 * margin;
  std::size_t carried = collision.GetTotalNumberOfCarriedCertificates();
  std::size_t certified = collision.GetTotalNumberOfCertifiedSteps();
  EXPECT_EQ(collision.Constrain(x.data(), y.data(), 0.0, nullptr, 1).constrained, 0u);
  EXPECT_EQ(collision.GetTotalNumberOfCarriedCertificates(), carried + 1);
  EXPECT_EQ(collision.GetTotalNumberOfCertifiedSteps(), certified + 1);
  // More than a 32nd of the points (9 of 258) moved by twice the margin:
  // the certificate again (a new margin, from these positions), not the
  // carried one.
  y = x;
  for (std::size_t i = 0; i <= n / 32; ++i)
  {
    y[3 * i] += 2.0 * margin;
  }
  carried = collision.GetTotalNumberOfCarriedCertificates();
  certified = collision.GetTotalNumberOfCertifiedSteps();
  EXPECT_EQ(collision.Constrain(x.data(), y.data(), 0.0, nullptr, 1).constrained, 0u);
  EXPECT_EQ(collision.GetTotalNumberOfCarriedCertificates(), carried);
  EXPECT_EQ(collision.GetTotalNumberOfCertifiedSteps(), certified + 1);
  EXPECT_GT(collision.GetCarriedMargin(), 0.0);
  // A new surface (SetSurface()) carries nothing; nor does a minimum
  // distance above 0 use the certificate.
  collision.SetSurface(n, triangles.data(), numberOfTriangles);
  EXPECT_EQ(collision.GetCarriedMargin(), 0.0);
  y = x;
  collision.Constrain(x.data(), y.data(), 0.1, nullptr, 1);
  EXPECT_EQ(collision.GetTotalNumberOfCertifiedSteps(), certified + 1);
  // Pushed through the sphere: neither the margin nor the certificate takes
  // it, the index stops the point.
  y = x;
  itk::SurfaceCollision pushed;
  pushed.SetSurface(n, triangles.data(), numberOfTriangles);
  EXPECT_EQ(pushed.Constrain(x.data(), y.data(), 0.0, nullptr, 1).constrained, 0u);
  ASSERT_GT(pushed.GetCarriedMargin(), 0.0);
  std::vector<double> through = PushedThrough(x);
  EXPECT_GT(pushed.Constrain(x.data(), through.data(), 0.0, nullptr, 1).constrained, 0u);
  EXPECT_EQ(CheckAllPairs(through, triangles, 0.0).intersecting, 0u);

  // Margins that do not last: every point goes out by three margins and
  // back at every step, so that no step is carried. A margin is computed
  // after the first certificate, then after waits of 1, 2 and 4
  // certificates.
  itk::SurfaceCollision jumpy;
  jumpy.SetSurface(n, triangles.data(), numberOfTriangles);
  std::string computed;
  for (int step = 0; step < 12; ++step)
  {
    y = x;
    if (step % 2 == 1)
    {
      for (std::size_t i = 0; i < n; ++i)
      {
        for (unsigned int d = 0; d < 3; ++d)
        {
          y[3 * i + d] += 3.0 * margin * (x[3 * i + d] - centre[d]) / 5.0;
        }
      }
    }
    EXPECT_EQ(jumpy.Constrain(x.data(), y.data(), 0.0, nullptr, 1).constrained, 0u);
    computed += jumpy.GetCarriedMargin() > 0.0 ? 'Y' : 'N';
  }
  EXPECT_EQ(jumpy.GetTotalNumberOfCertifiedSteps(), 12u);
  EXPECT_EQ(jumpy.GetTotalNumberOfCarriedCertificates(), 0u);
  EXPECT_EQ(computed, "YNYNNYNNNNYN");
}

TEST(SurfaceCollision, TheCarriedMarginIsTheLeastBoundOfAllTriangles)
{
  // The carried margin is (1 - 1e-6) times the least, over all triangles,
  // of f = d / (S1 + c S2 + c^2) (CarryCertificate()), which the
  // certificate's parallel pass finds while it skips the roots of most
  // triangles. Computed again here for every triangle, in long double, on
  // an uneven sphere of 8 192 triangles (8 blocks of 1 024), 2 threads.
  MeshType::PointType sphereCentre;
  sphereCentre[0] = 1.3;
  sphereCentre[1] = -0.7;
  sphereCentre[2] = 2.1;
  std::vector<double>   flat;
  std::vector<uint32_t> triangles;
  Flatten(itk::MakeSphereMesh<MeshType>(sphereCentre, 5.0, 5), flat, triangles);
  const std::vector<double> x = Inflate(flat, 0.6, 3);
  const std::size_t         n = x.size() / 3;
  const std::size_t         numberOfTriangles = triangles.size() / 3;
  ASSERT_EQ(numberOfTriangles, 8192u);
  auto threader = itk::MultiThreaderBase::New();
  threader->SetMaximumNumberOfThreads(2);
  itk::SurfaceCollision collision;
  collision.SetSurface(n, triangles.data(), numberOfTriangles);
  std::vector<double> y = x;
  EXPECT_EQ(collision.Constrain(x.data(), y.data(), 0.0, threader, 8).constrained, 0u);
  ASSERT_EQ(collision.GetTotalNumberOfCertifiedSteps(), 1u);
  const double margin = collision.GetCarriedMargin();
  ASSERT_GT(margin, 0.0);

  long double centre[3] = { 0.0L, 0.0L, 0.0L };
  for (std::size_t i = 0; i < n; ++i)
  {
    for (unsigned int d = 0; d < 3; ++d)
    {
      centre[d] += static_cast<long double>(x[3 * i + d]) / static_cast<long double>(n);
    }
  }
  const auto  cross = LongCross;
  const auto  dot = LongDot;
  long double least = std::numeric_limits<long double>::infinity();
  long double largest = 0.0L;
  for (std::size_t t = 0; t < numberOfTriangles; ++t)
  {
    long double q[3][3];
    for (unsigned int k = 0; k < 3; ++k)
    {
      for (unsigned int d = 0; d < 3; ++d)
      {
        q[k][d] = static_cast<long double>(x[3 * triangles[3 * t + k] + d]) - centre[d];
      }
    }
    long double bc[3], ca[3], ab[3];
    cross(q[1], q[2], bc);
    cross(q[2], q[0], ca);
    cross(q[0], q[1], ab);
    // |D|: the sphere's triangles all have one orientation seen from the
    // centre; the rounding bound r (about 1e-12 here) is left out.
    const long double d = std::abs(dot(q[0], bc));
    const long double s1 = std::sqrt(3.0L * (dot(bc, bc) + dot(ca, ca) + dot(ab, ab)));
    const long double s2 = std::sqrt(3.0L * (dot(q[0], q[0]) + dot(q[1], q[1]) + dot(q[2], q[2])));
    const long double c = d / s1;
    const long double f = d / (s1 + c * s2 + c * c);
    least = std::min(least, f);
    largest = std::max(largest, f);
  }
  const double expected = static_cast<double>((1.0L - 1e-6L) * least);
  EXPECT_NEAR(margin, expected, 1e-9 * expected);
  // Uneven enough that the least is not found by chance.
  EXPECT_GT(static_cast<double>(largest), 1.5 * expected);
  std::cout << "margin " << margin << ", least bound " << static_cast<double>(least) << ", largest "
            << static_cast<double>(largest) << std::endl;
}

TEST(SurfaceCollision, ASurfaceThatSlowsDownIsCarriedAgain)
{
  // A sphere that grows and shrinks by 5 carried margins at alternate steps
  // for 40 steps (every carried margin ends at the next step: the carries
  // wait 1, 2, 4, ... 64 certificates), then grows by a hundredth of a
  // margin a step. Told the
  // steps' lengths, the certificate ends the wait after two short steps and
  // carries the following ones; not told, it is still waiting 12 steps
  // later. Every step is certified either way.
  std::vector<double>   x0;
  std::vector<uint32_t> triangles;
  StarSphere(x0, triangles);
  const std::size_t n = x0.size() / 3;
  double            centre[3] = { 0.0, 0.0, 0.0 };
  for (std::size_t i = 0; i < n; ++i)
  {
    for (unsigned int d = 0; d < 3; ++d)
    {
      centre[d] += x0[3 * i + d] / static_cast<double>(n);
    }
  }
  double margin = 0.0;
  {
    itk::SurfaceCollision probe;
    probe.SetSurface(n, triangles.data(), triangles.size() / 3);
    std::vector<double> y = x0;
    probe.Constrain(x0.data(), y.data(), 0.0, nullptr, 1);
    margin = probe.GetCarriedMargin();
  }
  ASSERT_GT(margin, 0.0);
  const auto run = [&](bool giveSteps, itk::SizeValueType & certified) {
    itk::SurfaceCollision collision;
    collision.SetSurface(n, triangles.data(), triangles.size() / 3);
    std::vector<double> x = x0;
    itk::SizeValueType  carriedAtRest = 0;
    for (int step = 0; step < 52; ++step)
    {
      // Radially from the centre by `length` at every point.
      const double        length = step < 40 ? 5.0 * margin : 0.01 * margin;
      const double        sign = step < 40 && step % 2 == 1 ? -1.0 : 1.0;
      std::vector<double> y = x;
      for (std::size_t i = 0; i < n; ++i)
      {
        double r[3];
        double norm = 0.0;
        for (unsigned int d = 0; d < 3; ++d)
        {
          r[d] = x[3 * i + d] - centre[d];
          norm += r[d] * r[d];
        }
        norm = std::sqrt(norm);
        for (unsigned int d = 0; d < 3; ++d)
        {
          y[3 * i + d] += sign * length * r[d] / norm;
        }
      }
      const itk::SizeValueType carried = collision.GetTotalNumberOfCarriedCertificates();
      EXPECT_EQ(collision.Constrain(x.data(), y.data(), 0.0, nullptr, 1, giveSteps ? length : -1.0).constrained, 0u);
      if (step >= 40)
      {
        carriedAtRest += collision.GetTotalNumberOfCarriedCertificates() - carried;
      }
      if (step == 39)
      {
        EXPECT_EQ(collision.GetTotalNumberOfCarriedCertificates(), 0u) << "no margin lasts a step of 5 margins";
      }
      x = y;
    }
    certified = collision.GetTotalNumberOfCertifiedSteps();
    return carriedAtRest;
  };
  itk::SizeValueType certified = 0;
  EXPECT_EQ(run(true, certified), 10u) << "the wait ends after two short steps";
  EXPECT_EQ(certified, 52u);
  EXPECT_EQ(run(false, certified), 0u) << "without the steps' lengths, the wait of 64 certificates goes on";
  EXPECT_EQ(certified, 52u);
}

TEST(SurfaceCollision, TheCertificateFollowsTheTrianglesOfPointsBeyondItsMargin)
{
  // From a carried certificate, steps that move up to 8 of the 258 points
  // (a 32nd) far beyond the margin, each toward a random point within 1.2
  // edge lengths, or through the sphere: a step left as proposed
  // (constrained 0) is free of intersecting pairs by the test of all pairs,
  // and star-shaped by a fresh certificate when no point went through.
  // Both ways are taken: steps carried past the margin, and steps that the
  // certificate, the folds' test or the index decided.
  std::vector<double>   x;
  std::vector<uint32_t> triangles;
  StarSphere(x, triangles);
  const std::size_t n = x.size() / 3;
  const std::size_t numberOfTriangles = triangles.size() / 3;
  std::mt19937      random(11);
  // A step from the certified positions \a from to \a y: left as proposed
  // unless constrained, free of intersecting pairs, and star-shaped by a
  // fresh certificate when carried. Returns whether it was carried, and
  // whether it was constrained.
  const auto step = [&](itk::SurfaceCollision &     collision,
                        const std::vector<double> & from,
                        std::vector<double> &       y,
                        int                         trial) -> std::pair<bool, bool> {
    const std::vector<double> proposed = y;
    const std::size_t         carried = collision.GetTotalNumberOfCarriedCertificates();
    const auto                result = collision.Constrain(from.data(), y.data(), 0.0, nullptr, 1);
    const bool                carriedNow = collision.GetTotalNumberOfCarriedCertificates() > carried;
    EXPECT_EQ(CheckAllPairs(y, triangles, 0.0).intersecting, 0u) << "trial " << trial;
    if (result.constrained == 0)
    {
      EXPECT_EQ(y, proposed);
    }
    if (carriedNow)
    {
      itk::SurfaceCollision fresh;
      fresh.SetSurface(n, triangles.data(), numberOfTriangles);
      EXPECT_TRUE(fresh.IsStarShaped(y.data())) << "trial " << trial;
    }
    return { carriedNow, result.constrained > 0 };
  };
  std::size_t carriedPast = 0;
  std::size_t decidedOtherwise = 0;
  std::size_t throughCaught = 0;
  for (int trial = 0; trial < 120; ++trial)
  {
    itk::SurfaceCollision collision;
    collision.SetSurface(n, triangles.data(), numberOfTriangles);
    std::vector<double> y = x;
    ASSERT_EQ(collision.Constrain(x.data(), y.data(), 0.0, nullptr, 1).constrained, 0u);
    const double margin = collision.GetCarriedMargin();
    ASSERT_GT(margin, 0.0);
    const bool                                 through = trial % 4 == 3;
    const std::size_t                          moved = 1 + static_cast<std::size_t>(trial) % 8;
    std::uniform_int_distribution<std::size_t> pick(0, n - 1);
    std::normal_distribution<double>           normal(0.0, 1.0);
    std::vector<std::size_t>                   chosen;
    for (std::size_t m = 0; m < moved; ++m)
    {
      std::size_t i = pick(random);
      while (std::find(chosen.begin(), chosen.end(), i) != chosen.end())
      {
        i = pick(random);
      }
      chosen.push_back(i);
      if (through && m == 0)
      {
        const double centre[3] = { 1.3, -0.7, 2.1 };
        for (unsigned int d = 0; d < 3; ++d)
        {
          y[3 * i + d] = centre[d] - 1.5 * (x[3 * i + d] - centre[d]);
        }
        continue;
      }
      const double scale = 1.2 * 1.1 * std::abs(normal(random)) / std::sqrt(3.0);
      for (unsigned int d = 0; d < 3; ++d)
      {
        y[3 * i + d] = x[3 * i + d] + scale * normal(random);
      }
    }
    const auto [carriedNow, constrained] = step(collision, x, y, trial);
    carriedPast += carriedNow ? 1 : 0;
    decidedOtherwise += carriedNow ? 0 : 1;
    EXPECT_FALSE(carriedNow && through) << "trial " << trial << ": a point through the sphere carried";
    if (through)
    {
      throughCaught += constrained ? 1 : 0;
    }
  }
  std::cout << carriedPast << " steps carried past the margin, " << decidedOtherwise << " decided otherwise, "
            << throughCaught << " of 30 through the sphere constrained" << std::endl;
  EXPECT_GT(carriedPast, 20u);
  EXPECT_GT(decidedOtherwise, 20u);
  EXPECT_EQ(throughCaught, 30u);

  // Nearer moves: up to 8 points moved by 1 to 8 carried margins, in random
  // directions, from a sphere whose points were first jittered by 5 % of an
  // edge (so that the triangles' own margins differ). A step carried must be
  // star-shaped by a fresh certificate and free of intersecting pairs; some
  // triangles are kept by their own margins (WithinOwnMargin()), and some
  // steps still need the exact signs or a certificate.
  std::vector<double> jittered = x;
  {
    std::normal_distribution<double> normal(0.0, 1.0);
    for (double & v : jittered)
    {
      v += 0.05 * 1.1 * normal(random) / std::sqrt(3.0);
    }
  }
  std::size_t byOwnMargins = 0;
  std::size_t nearCarried = 0;
  std::size_t nearOtherwise = 0;
  for (int trial = 0; trial < 120; ++trial)
  {
    itk::SurfaceCollision collision;
    collision.SetSurface(n, triangles.data(), numberOfTriangles);
    std::vector<double> y = jittered;
    ASSERT_EQ(collision.Constrain(jittered.data(), y.data(), 0.0, nullptr, 1).constrained, 0u);
    const double margin = collision.GetCarriedMargin();
    ASSERT_GT(margin, 0.0);
    std::uniform_int_distribution<std::size_t> pick(0, n - 1);
    std::normal_distribution<double>           normal(0.0, 1.0);
    const std::size_t                          moved = 1 + static_cast<std::size_t>(trial) % 8;
    for (std::size_t m = 0; m < moved; ++m)
    {
      const std::size_t i = pick(random);
      double            v[3] = { normal(random), normal(random), normal(random) };
      const double      length = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
      const double      distance = margin * (1.0 + 7.0 * static_cast<double>(trial % 15) / 14.0);
      for (unsigned int d = 0; d < 3; ++d)
      {
        y[3 * i + d] = jittered[3 * i + d] + distance * v[d] / length;
      }
    }
    const std::size_t within = collision.GetTotalNumberOfTrianglesWithinOwnMargin();
    const bool        carriedNow = step(collision, jittered, y, trial).first;
    byOwnMargins += collision.GetTotalNumberOfTrianglesWithinOwnMargin() - within;
    nearCarried += carriedNow ? 1 : 0;
    nearOtherwise += carriedNow ? 0 : 1;
  }
  std::cout << nearCarried << " near steps carried, " << nearOtherwise << " decided otherwise, " << byOwnMargins
            << " triangles kept by their own margins" << std::endl;
  EXPECT_GT(byOwnMargins, 100u);
  EXPECT_GT(nearCarried, 60u);
}

// Each point's neighbours in the cyclic order of its triangles (i, r_k,
// r_k+1), chained from the triangles' own orders: the fans that
// SetPointFans() takes (DeformableMeshFilter passes its rings).
namespace
{
void
PointFans(const std::vector<uint32_t> & triangles,
          std::size_t                   n,
          std::vector<uint32_t> &       offsets,
          std::vector<uint32_t> &       neighbours)
{
  std::vector<std::vector<std::pair<uint32_t, uint32_t>>> pairs(n);
  for (std::size_t c = 0; c < triangles.size(); c += 3)
  {
    for (unsigned int k = 0; k < 3; ++k)
    {
      pairs[triangles[c + k]].emplace_back(triangles[c + (k + 1) % 3], triangles[c + (k + 2) % 3]);
    }
  }
  offsets.assign(1, 0);
  neighbours.clear();
  for (std::size_t i = 0; i < n; ++i)
  {
    const auto & fan = pairs[i];
    if (!fan.empty())
    {
      uint32_t next = fan.front().first;
      for (std::size_t k = 0; k < fan.size(); ++k)
      {
        neighbours.push_back(next);
        const auto pair = std::find_if(
          fan.begin(), fan.end(), [next](const std::pair<uint32_t, uint32_t> & p) { return p.first == next; });
        next = pair->second;
      }
    }
    offsets.push_back(static_cast<uint32_t>(neighbours.size()));
  }
}
} // namespace

TEST(SurfaceCollision, PointFansGiveTheScanDecisions)
{
  // The carried certificate through the fans of the points beyond its
  // margin (SetPointFans(): their own margins, then the triangles of those
  // beyond them) decides as the pass over all the triangles: the same
  // steps carried, the same positions, from a jittered sphere with 1 to 8
  // points moved by 1 to 10 carried margins, or through the sphere. Every
  // step carried is star-shaped by a fresh certificate and free of
  // intersecting pairs by the test of all pairs. Some points are cleared by
  // their own margins, and some are not (their triangles tested).
  std::vector<double>   x;
  std::vector<uint32_t> triangles;
  StarSphere(x, triangles);
  const std::size_t     n = x.size() / 3;
  const std::size_t     numberOfTriangles = triangles.size() / 3;
  std::vector<uint32_t> offsets;
  std::vector<uint32_t> neighbours;
  PointFans(triangles, n, offsets, neighbours);
  ASSERT_EQ(offsets.back(), triangles.size());
  std::mt19937                     random(20261207);
  std::normal_distribution<double> normal(0.0, 1.0);
  for (double & v : x)
  {
    v += 0.05 * 1.1 * normal(random) / std::sqrt(3.0);
  }
  std::size_t carried = 0;
  std::size_t otherwise = 0;
  std::size_t pointsCleared = 0;
  std::size_t trianglesTested = 0;
  for (int trial = 0; trial < 240; ++trial)
  {
    itk::SurfaceCollision withFans;
    itk::SurfaceCollision scanning;
    for (itk::SurfaceCollision * collision : { &withFans, &scanning })
    {
      collision->SetSurface(n, triangles.data(), numberOfTriangles);
      std::vector<double> y = x;
      ASSERT_EQ(collision->Constrain(x.data(), y.data(), 0.0, nullptr, 1).constrained, 0u);
      ASSERT_GT(collision->GetCarriedMargin(), 0.0);
    }
    ASSERT_EQ(withFans.GetCarriedMargin(), scanning.GetCarriedMargin());
    const double                               margin = withFans.GetCarriedMargin();
    std::uniform_int_distribution<std::size_t> pick(0, n - 1);
    std::vector<double>                        y = x;
    const std::size_t                          moved = 1 + static_cast<std::size_t>(trial) % 8;
    const bool                                 through = trial % 10 == 9;
    for (std::size_t m = 0; m < moved; ++m)
    {
      const std::size_t i = pick(random);
      if (through && m == 0)
      {
        const double centre[3] = { 1.3, -0.7, 2.1 };
        for (unsigned int d = 0; d < 3; ++d)
        {
          y[3 * i + d] = centre[d] - 1.5 * (x[3 * i + d] - centre[d]);
        }
        continue;
      }
      double       v[3] = { normal(random), normal(random), normal(random) };
      const double length = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
      const double distance = margin * (1.0 + 9.0 * static_cast<double>(trial % 23) / 22.0);
      for (unsigned int d = 0; d < 3; ++d)
      {
        y[3 * i + d] = x[3 * i + d] + distance * v[d] / length;
      }
    }
    std::vector<double> yFans = y;
    std::vector<double> yScan = y;
    const std::size_t   cleared = withFans.GetTotalNumberOfPointsWithinOwnMargin();
    const std::size_t   tested = withFans.GetTotalNumberOfTrianglesWithinOwnMargin();
    withFans.SetPointFans(offsets.data(), neighbours.data());
    withFans.Constrain(x.data(), yFans.data(), 0.0, nullptr, 1);
    withFans.SetPointFans(nullptr, nullptr);
    scanning.Constrain(x.data(), yScan.data(), 0.0, nullptr, 1);
    pointsCleared += withFans.GetTotalNumberOfPointsWithinOwnMargin() - cleared;
    trianglesTested += withFans.GetTotalNumberOfTrianglesWithinOwnMargin() - tested;
    const bool carriedNow = withFans.GetTotalNumberOfCarriedCertificates() > 0;
    EXPECT_EQ(carriedNow, scanning.GetTotalNumberOfCarriedCertificates() > 0) << "trial " << trial;
    EXPECT_EQ(yFans, yScan) << "trial " << trial;
    EXPECT_EQ(CheckAllPairs(yFans, triangles, 0.0).intersecting, 0u) << "trial " << trial;
    if (carriedNow)
    {
      EXPECT_FALSE(through) << "trial " << trial << ": a point through the sphere carried";
      itk::SurfaceCollision fresh;
      fresh.SetSurface(n, triangles.data(), numberOfTriangles);
      EXPECT_TRUE(fresh.IsStarShaped(yFans.data())) << "trial " << trial;
    }
    carried += carriedNow ? 1 : 0;
    otherwise += carriedNow ? 0 : 1;
  }
  std::cout << carried << " steps carried, " << otherwise << " decided otherwise; " << pointsCleared
            << " points cleared by their own margins, " << trianglesTested
            << " triangles of the others kept by their own margins" << std::endl;
  EXPECT_GT(carried, 50u);
  EXPECT_GT(otherwise, 24u);
  EXPECT_GT(pointsCleared, 20u);
  EXPECT_GT(trianglesTested, 20u);

  // Fans that cannot describe the triangles (not three corners a triangle)
  // are ignored; SetSurface() drops the fans.
  itk::SurfaceCollision collision;
  collision.SetSurface(n, triangles.data(), numberOfTriangles);
  std::vector<double> y = x;
  ASSERT_EQ(collision.Constrain(x.data(), y.data(), 0.0, nullptr, 1).constrained, 0u);
  std::vector<uint32_t> short_ = offsets;
  short_.back() -= 1;
  y[0] += 3.0 * collision.GetCarriedMargin();
  collision.SetPointFans(short_.data(), neighbours.data());
  collision.Constrain(x.data(), y.data(), 0.0, nullptr, 1);
  EXPECT_EQ(collision.GetTotalNumberOfPointsWithinOwnMargin(), 0u);
  collision.SetPointFans(offsets.data(), neighbours.data());
  collision.SetSurface(n, triangles.data(), numberOfTriangles);
  y = x;
  ASSERT_EQ(collision.Constrain(x.data(), y.data(), 0.0, nullptr, 1).constrained, 0u);
  y[0] += 3.0 * collision.GetCarriedMargin();
  collision.Constrain(x.data(), y.data(), 0.0, nullptr, 1);
  EXPECT_EQ(collision.GetTotalNumberOfPointsWithinOwnMargin(), 0u);
}

TEST(SurfaceCollision, TheCertificateTakesFoldsThatMeetNothing)
{
  std::vector<double>   x;
  std::vector<uint32_t> triangles;
  StarSphere(x, triangles);
  const std::size_t     n = x.size() / 3;
  itk::SurfaceCollision collision;
  collision.SetSurface(n, triangles.data(), triangles.size() / 3);
  EXPECT_TRUE(collision.IsStarShapedUpToFolds(x.data()));

  // Point 0 pulled sideways until one of its triangles turns its back to
  // the centre, without intersecting: not star-shaped, but the fold's
  // neighbourhood has no meeting pair.
  const std::vector<double> leaning = Leaning(x);
  ASSERT_EQ(CheckAllPairs(leaning, triangles, 0.0).intersecting, 0u);
  ASSERT_EQ(CountFoldedFans(leaning, triangles), 0u);
  EXPECT_FALSE(collision.IsStarShaped(leaning.data()));
  EXPECT_TRUE(collision.IsStarShapedUpToFolds(leaning.data()));
  // Point 0 pushed through the sphere: refused.
  EXPECT_FALSE(collision.IsStarShapedUpToFolds(PushedThrough(x).data()));

  // One to three points thrown by up to 6 (the radius is 5): every surface
  // the certificate takes has no intersecting pair and no folded fan (both
  // counted here by brute force, with predicates of this test's own); it
  // takes folds that the star-shaped test refuses, and refuses surfaces
  // that meet themselves.
  std::mt19937                           random(20261205);
  std::uniform_real_distribution<double> throwing(-6.0, 6.0);
  std::uniform_int_distribution<int>     howMany(1, 3);
  std::uniform_int_distribution<int>     which(0, static_cast<int>(n) - 1);
  unsigned int                           takenFolds = 0;
  unsigned int                           refusedMeeting = 0;
  for (unsigned int trial = 0; trial < 400; ++trial)
  {
    std::vector<double> y = x;
    for (int k = howMany(random); k > 0; --k)
    {
      const auto   i = static_cast<std::size_t>(which(random));
      const double scale = std::uniform_real_distribution<double>(0.05, 1.0)(random);
      for (unsigned int d = 0; d < 3; ++d)
      {
        y[3 * i + d] += scale * throwing(random);
      }
    }
    const bool meets = CheckAllPairs(y, triangles, 0.0).intersecting > 0 || CountFoldedFans(y, triangles) > 0;
    const bool taken = collision.IsStarShapedUpToFolds(y.data());
    EXPECT_FALSE(taken && meets) << "trial " << trial;
    takenFolds += taken && !collision.IsStarShaped(y.data()) ? 1 : 0;
    refusedMeeting += !taken && meets ? 1 : 0;
  }
  std::cout << takenFolds << " folds taken, " << refusedMeeting << " meeting surfaces refused of 400" << std::endl;
  EXPECT_GT(takenFolds, 20u);
  EXPECT_GT(refusedMeeting, 20u);
}

TEST(SurfaceCollision, CertifiedStepsGiveWhatTheIndexGives)
{
  // A sphere inflating unevenly (star-shaped at every step), then deflating
  // through its centre (its fronts meet there), with minimum distance 0:
  // with the certificate and without, the same positions at every step, no
  // intersecting pair (all-pairs test); with it the inflating steps need no
  // index. With a minimum distance above 0 the certificate is not used.
  std::vector<double>   x;
  std::vector<uint32_t> triangles;
  StarSphere(x, triangles);
  const std::size_t     n = x.size() / 3;
  itk::SurfaceCollision certified;
  itk::SurfaceCollision indexed;
  certified.SetSurface(n, triangles.data(), triangles.size() / 3);
  indexed.SetSurface(n, triangles.data(), triangles.size() / 3);
  indexed.SetUseStarShapedCertificate(false);
  std::vector<double> a = x;
  std::vector<double> b = x;
  unsigned int        constrained = 0;
  for (unsigned int step = 0; step < 20; ++step)
  {
    // Out for 10 steps, then in by 1.2 a step, through the centre.
    const double        grow = step < 10 ? 0.4 : -1.2;
    std::vector<double> ya = Inflate(a, grow, step);
    std::vector<double> yb = Inflate(b, grow, step);
    ASSERT_EQ(ya, yb);
    const auto ra = certified.Constrain(a.data(), ya.data(), 0.0, nullptr, 1);
    const auto rb = indexed.Constrain(b.data(), yb.data(), 0.0, nullptr, 1);
    ASSERT_EQ(ya, yb) << "step " << step;
    EXPECT_EQ(ra.constrained, rb.constrained) << "step " << step;
    EXPECT_EQ(CheckAllPairs(ya, triangles, 0.0).intersecting, 0u) << "step " << step;
    if (step == 9)
    {
      EXPECT_EQ(certified.GetNumberOfCertifiedSteps(), 10u) << "every inflating step";
      EXPECT_EQ(certified.GetNumberOfRebuilds(), 0u);
      EXPECT_GE(indexed.GetNumberOfRebuilds(), 1u);
    }
    constrained += rb.constrained > 0 ? 1 : 0;
    a = ya;
    b = yb;
  }
  EXPECT_GE(constrained, 5u) << "the fronts met";
  EXPECT_EQ(indexed.GetNumberOfCertifiedSteps(), 0u);

  // A minimum distance above 0: the index.
  itk::SurfaceCollision withDistance;
  withDistance.SetSurface(n, triangles.data(), triangles.size() / 3);
  std::vector<double> y = Inflate(x, 0.4, 0);
  withDistance.Constrain(x.data(), y.data(), 0.05, nullptr, 1);
  EXPECT_EQ(withDistance.GetNumberOfCertifiedSteps(), 0u);
  EXPECT_EQ(withDistance.GetNumberOfRebuilds(), 1u);
}

TEST(SurfaceCollision, AfterAFailureTheCertificateWaitsLongerEachTime)
{
  // A step that the certificate refuses (a point pushed through the
  // surface), then star-shaped steps: the certificate is not tried at the
  // next 1, then after a second failure the next 2 calls; a success resets
  // the wait.
  std::vector<double>   x;
  std::vector<uint32_t> triangles;
  StarSphere(x, triangles);
  itk::SurfaceCollision collision;
  collision.SetSurface(x.size() / 3, triangles.data(), triangles.size() / 3);
  const auto step = [&](bool crossing) {
    std::vector<double>      y = crossing ? PushedThrough(x) : x;
    const itk::SizeValueType before = collision.GetNumberOfCertifiedSteps();
    collision.Constrain(x.data(), y.data(), 0.0, nullptr, 1);
    return collision.GetNumberOfCertifiedSteps() > before;
  };
  EXPECT_TRUE(step(false));
  EXPECT_FALSE(step(true));
  EXPECT_FALSE(step(false)) << "waits 1";
  EXPECT_TRUE(step(false));
  EXPECT_FALSE(step(true));
  EXPECT_FALSE(step(false)) << "waits 1 (the success reset the wait)";
  EXPECT_FALSE(step(true));
  EXPECT_FALSE(step(false)) << "waits 2";
  EXPECT_FALSE(step(false)) << "waits 2";
  EXPECT_TRUE(step(false));
  // FindContacts() on a star-shaped surface at distance 0: no contact, by
  // the certificate.
  std::vector<uint8_t>     contacts;
  const itk::SizeValueType before = collision.GetNumberOfCertifiedSteps();
  EXPECT_EQ(collision.FindContacts(x.data(), nullptr, 0.0, contacts, nullptr, 1), 0u);
  EXPECT_EQ(collision.GetNumberOfCertifiedSteps(), before + 1);
  EXPECT_EQ(contacts.size(), triangles.size() / 3);
}

TEST(SurfaceCollision, CertifyContactsIsFindContactsFirstTest)
{
  // CertifyContacts() answers as FindContacts()'s certificate: true on a
  // star-shaped surface at distance 0 (counted as a certified step), false
  // where the certificate does not apply (a minimum distance above 0) or
  // refuses (a point pushed through the surface); FindContacts() told not to
  // try it again then finds the contacts with the index, without a
  // certified step.
  std::vector<double>   x;
  std::vector<uint32_t> triangles;
  StarSphere(x, triangles);
  const itk::SizeValueType numberOfTriangles = triangles.size() / 3;
  itk::SurfaceCollision    collision;
  collision.SetSurface(x.size() / 3, triangles.data(), numberOfTriangles);
  itk::SizeValueType certified = collision.GetNumberOfCertifiedSteps();
  EXPECT_TRUE(collision.CertifyContacts(x.data(), 0.0, nullptr, 1));
  EXPECT_EQ(collision.GetNumberOfCertifiedSteps(), certified + 1);
  certified = collision.GetNumberOfCertifiedSteps();
  EXPECT_FALSE(collision.CertifyContacts(x.data(), 0.5, nullptr, 1)) << "no certificate above distance 0";
  EXPECT_EQ(collision.GetNumberOfCertifiedSteps(), certified);

  const std::vector<double> through = PushedThrough(x);
  const itk::SizeValueType  intersecting = CheckAllPairs(through, triangles, 0.0).intersecting;
  ASSERT_GT(intersecting, 0u);
  itk::SurfaceCollision pushed;
  pushed.SetSurface(x.size() / 3, triangles.data(), numberOfTriangles);
  EXPECT_FALSE(pushed.CertifyContacts(through.data(), 0.0, nullptr, 1));
  std::vector<uint8_t> contacts;
  EXPECT_GE(pushed.FindContacts(through.data(), nullptr, 0.0, contacts, nullptr, 1, false), intersecting);
  EXPECT_EQ(pushed.GetNumberOfCertifiedSteps(), 0u);
  ASSERT_EQ(contacts.size(), numberOfTriangles);
  EXPECT_GT(std::count(contacts.begin(), contacts.end(), uint8_t{ 1 }), 0);
  // The same surface from a fresh collision test, certificate allowed:
  // the same number of pairs.
  itk::SurfaceCollision fresh;
  fresh.SetSurface(x.size() / 3, triangles.data(), numberOfTriangles);
  std::vector<uint8_t> freshContacts;
  EXPECT_EQ(fresh.FindContacts(through.data(), nullptr, 0.0, freshContacts, nullptr, 1),
            pushed.FindContacts(through.data(), nullptr, 0.0, contacts, nullptr, 1, false));
  EXPECT_EQ(freshContacts, contacts);
}

namespace
{
/** Statistics of RandomSteps(). */
struct RandomStepsResult
{
  unsigned int constrainedSteps{ 0 };
  unsigned int keptIndex{ 0 };
  unsigned int secondTranslations{ 0 };
  unsigned int secondTranslationRebuilds{ 0 };
  std::size_t  largeTriangles{ 0 }; // most seen after a Constrain()
};

/** 80 steps of random smooth displacements of the two sheets of \a x that
 * push them through each other and back, with a tangential wave and every
 * fifth and sixth step a translation of the whole surface by 1.9; after
 * every Constrain() (minimum distance \a d) no intersecting pair and no
 * pair closer than d, by this file's all-pairs test. */
RandomStepsResult
RandomSteps(std::vector<double> x, const std::vector<uint32_t> & triangles, double d)
{
  RandomStepsResult     stats;
  const std::size_t     n = x.size() / 3;
  itk::SurfaceCollision collision;
  collision.SetSurface(n, triangles.data(), triangles.size() / 3);
  std::mt19937                           random(20261202);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  for (unsigned int step = 0; step < 80; ++step)
  {
    std::vector<double> y = x;
    const bool          translation = step % 6 == 4 || step % 6 == 5;
    if (translation)
    {
      for (std::size_t i = 0; i < n; ++i)
      {
        y[3 * i] += 1.5;
        y[3 * i + 1] -= 0.7;
        y[3 * i + 2] += 0.9;
      }
    }
    else
    {
      const double amplitude = -0.2 + 0.6 * uniform(random);
      const double cx = x[0] + 6.0 * uniform(random);
      const double cy = x[1] + 6.0 * uniform(random);
      const double phase = 6.28 * uniform(random);
      for (std::size_t i = 0; i < n; ++i)
      {
        const double px = x[3 * i] - cx, py = x[3 * i + 1] - cy;
        const double bump = amplitude * std::exp(-(px * px + py * py) / 4.0);
        y[3 * i] += 0.05 * std::sin(1.3 * x[3 * i + 1] + phase);
        y[3 * i + 1] += 0.05 * std::cos(0.9 * x[3 * i] + phase);
        y[3 * i + 2] += i >= n / 2 ? -bump : bump;
      }
    }
    const auto       result = collision.Constrain(x.data(), y.data(), d, nullptr, 1);
    const BruteForce check = CheckAllPairs(y, triangles, d);
    EXPECT_EQ(check.intersecting, 0u) << "step " << step;
    EXPECT_GE(check.smallestDistance, d - 1e-9) << "step " << step;
    if (check.intersecting != 0 || !(check.smallestDistance >= d - 1e-9))
    {
      return stats;
    }
    stats.constrainedSteps += result.constrained > 0 ? 1 : 0;
    stats.keptIndex += result.rebuilt ? 0 : 1;
    stats.largeTriangles = std::max<std::size_t>(stats.largeTriangles, collision.GetNumberOfLargeTriangles());
    if (step % 6 == 5)
    {
      ++stats.secondTranslations;
      stats.secondTranslationRebuilds += result.rebuilt ? 1 : 0;
    }
    x = y;
  }
  return stats;
}
} // namespace

TEST(SurfaceCollision, RandomStepsNeverBringPairsCloserThanD)
{
  // Two parallel sheets 1 apart (edges 0.5), RandomSteps() with d = 0.1.
  // A translation moves no triangle relative to another: the second of two
  // translations keeps the index (the first may follow a rebuild).
  std::vector<double>   x;
  std::vector<uint32_t> triangles;
  TwoSheets(1.0, x, triangles);
  const double d = 0.1;
  ASSERT_GE(CheckAllPairs(x, triangles, d).smallestDistance, d);
  const RandomStepsResult stats = RandomSteps(x, triangles, d);
  EXPECT_GE(stats.constrainedSteps, 10u) << "the sheets were pushed into each other";
  EXPECT_GE(stats.keptIndex, 20u) << "the index served several steps";
  EXPECT_EQ(stats.secondTranslationRebuilds, 0u) << "of " << stats.secondTranslations << " second translations";
  EXPECT_EQ(stats.largeTriangles, 0u) << "an even mesh: every triangle in the cells";
  std::cout << stats.constrainedSteps << " steps constrained, the index kept at " << stats.keptIndex << " of 80 steps"
            << std::endl;
}

TEST(SurfaceCollision, RandomStepsWithLargeTrianglesNeverBringPairsCloserThanD)
{
  // The same with one corner of each sheet pulled out by (1.5, -1.5): the
  // one triangle at that corner of each sheet is several times larger than
  // the others, in no cell of the index (a large triangle): its pairs are
  // found through the grid of boxes, at the rebuilds and at every step.
  std::vector<double>   x;
  std::vector<uint32_t> triangles;
  TwoSheetsWithLargeCorners(1.0, x, triangles);
  const double d = 0.1;
  ASSERT_GE(CheckAllPairs(x, triangles, d).smallestDistance, d);
  const RandomStepsResult stats = RandomSteps(x, triangles, d);
  EXPECT_GE(stats.constrainedSteps, 10u) << "the sheets were pushed into each other";
  EXPECT_EQ(stats.largeTriangles, 2u) << "the two corner triangles";
}

TEST(SurfaceCollision, ALargeTriangleStopsAtDBelowSmallOnes)
{
  // Two sheets 0.3 apart (d = 0.1), the lower one's corner point 12 pulled
  // out by (1.5, -1.5) (one large triangle, in no cell) and the upper one
  // moved by (1.6, -1.6) so that its small triangles cover the large one.
  // Only the pulled-out corner rises, by 0.05 a step: the pairs of the
  // large triangle with the small ones above it are found only by the
  // large triangles' candidate search (the cells of the small triangles
  // around it, at each rebuild), and only those candidates are tested while
  // its motion stays below R - d. Unconstrained, the corner would pass the
  // upper sheet.
  std::vector<double>   x;
  std::vector<uint32_t> triangles;
  TwoSheets(0.3, x, triangles);
  const std::size_t n = x.size() / 3;
  x[3 * 12] += 1.5;
  x[3 * 12 + 1] -= 1.5;
  for (std::size_t i = n / 2; i < n; ++i)
  {
    x[3 * i] += 1.6;
    x[3 * i + 1] -= 1.6;
  }
  const double d = 0.1;
  ASSERT_GE(CheckAllPairs(x, triangles, d).smallestDistance, d);
  itk::SurfaceCollision collision;
  collision.SetSurface(n, triangles.data(), triangles.size() / 3);
  double unconstrained = std::numeric_limits<double>::infinity();
  for (unsigned int step = 0; step < 10; ++step)
  {
    std::vector<double> y = x;
    y[3 * 12 + 2] += 0.05;
    unconstrained = std::min(unconstrained, CheckAllPairs(y, triangles, d).smallestDistance);
    collision.Constrain(x.data(), y.data(), d, nullptr, 1);
    EXPECT_EQ(collision.GetNumberOfLargeTriangles(), 1u);
    const BruteForce check = CheckAllPairs(y, triangles, d);
    ASSERT_EQ(check.intersecting, 0u) << "step " << step;
    ASSERT_GE(check.smallestDistance, d - 1e-9) << "step " << step;
    x = y;
  }
  EXPECT_LT(unconstrained, d) << "the proposed steps would have come within d";
  EXPECT_LT(x[3 * 12 + 2], 0.3) << "the corner stopped below the upper sheet";
}

TEST(SurfaceCollision, AFanMovingAloneIsDeferredAndStopsAtD)
{
  // Two sheets of 25 x 25 points 1.2 apart (edges 0.5, d = 0.1, so
  // R = d + 0.75 mean edges, about 0.53): the middle point of the lower
  // sheet rises by 0.1 a step, nothing else moves. Its six triangles move
  // against the cells around them; from a motion of R - d their pairs with
  // the upper sheet (no candidates at the reference, 1.2 apart) are no
  // longer bounded by the index: the triangles are deferred and query the
  // grid of the reference boxes at every step, instead of the index being
  // rebuilt. Without those queries the point passes the upper sheet (z = 2
  // after 20 steps, no pair seen); unconstrained it would too.
  std::vector<double>   x;
  std::vector<uint32_t> triangles;
  const unsigned int    m = 24;
  TwoSheets(1.2, x, triangles, m);
  const std::size_t n = x.size() / 3;
  const std::size_t p = (m / 2) * (m + 1) + m / 2;
  const double      d = 0.1;
  ASSERT_GE(CheckAllPairs(x, triangles, d).smallestDistance, d);
  itk::SurfaceCollision collision;
  collision.SetSurface(n, triangles.data(), triangles.size() / 3);
  double       unconstrained = std::numeric_limits<double>::infinity();
  unsigned int deferredSteps = 0;
  unsigned int constrainedSteps = 0;
  for (unsigned int step = 0; step < 20; ++step)
  {
    std::vector<double> y = x;
    y[3 * p + 2] += 0.1;
    unconstrained = std::min(unconstrained, CheckAllPairs(y, triangles, d).smallestDistance);
    const auto result = collision.Constrain(x.data(), y.data(), d, nullptr, 1);
    deferredSteps += collision.GetNumberOfDeferredTriangles() > 0 ? 1 : 0;
    constrainedSteps += result.constrained > 0 ? 1 : 0;
    const BruteForce check = CheckAllPairs(y, triangles, d);
    ASSERT_EQ(check.intersecting, 0u) << "step " << step;
    ASSERT_GE(check.smallestDistance, d - 1e-9) << "step " << step;
    x = y;
  }
  EXPECT_LT(unconstrained, d) << "the proposed steps would have come within d";
  EXPECT_LT(x[3 * p + 2], 1.2 - d + 1e-9) << "the point stopped below the upper sheet";
  EXPECT_GE(deferredSteps, 3u) << "the fan's pairs were found by its grid queries";
  EXPECT_GE(constrainedSteps, 1u);
  EXPECT_LE(collision.GetNumberOfRebuilds(), 2u) << "a fan moving alone does not rebuild the index";
  std::cout << deferredSteps << " steps with deferred triangles, " << collision.GetNumberOfRebuilds() << " rebuilds"
            << std::endl;
}

TEST(SurfaceCollision, ALargeTriangleMovingAloneStopsAtD)
{
  // Two sheets 0.3 apart (d = 0.1) with the same corner of each pulled out
  // by (1.5, -1.5): two large triangles, one above the other. Only the
  // lower one's pulled-out corner rises, by 0.05 a step: no triangle of any
  // cell moves, so only the large triangles' test at every step can see the
  // pair come closer (while the motion is below R - d, through their
  // candidate pairs). Unconstrained, the corner would pass the upper sheet.
  std::vector<double>   x;
  std::vector<uint32_t> triangles;
  TwoSheetsWithLargeCorners(0.3, x, triangles);
  const std::size_t n = x.size() / 3;
  const double      d = 0.1;
  ASSERT_GE(CheckAllPairs(x, triangles, d).smallestDistance, d);
  itk::SurfaceCollision collision;
  collision.SetSurface(n, triangles.data(), triangles.size() / 3);
  double unconstrained = std::numeric_limits<double>::infinity();
  for (unsigned int step = 0; step < 10; ++step)
  {
    std::vector<double> y = x;
    y[3 * 12 + 2] += 0.05;
    unconstrained = std::min(unconstrained, CheckAllPairs(y, triangles, d).smallestDistance);
    collision.Constrain(x.data(), y.data(), d, nullptr, 1);
    EXPECT_EQ(collision.GetNumberOfLargeTriangles(), 2u);
    const BruteForce check = CheckAllPairs(y, triangles, d);
    ASSERT_EQ(check.intersecting, 0u) << "step " << step;
    ASSERT_GE(check.smallestDistance, d - 1e-9) << "step " << step;
    x = y;
  }
  EXPECT_LT(unconstrained, d) << "the proposed steps would have come within d";
  EXPECT_LT(x[3 * 12 + 2], 0.3) << "the corner stopped below the upper sheet";
}

// ---------------------------------------------------------------------------
// DeformableMeshFilter with PreventSelfIntersections.
namespace
{
using ImageType = itk::Image<unsigned char, 3>;
using ForceImageType = itk::Image<itk::CovariantVector<float, 3>, 3>;
using FilterType = itk::DeformableMeshFilter<MeshType, ForceImageType>;

/** Shrink-wrap onto two ellipsoids of radii (10, 8, 8) voxels whose tips
 * are 1.5 voxels apart along x, in a 64 x 56 x 56 image of unit spacing:
 * a sphere of radius 23 around both deflates (balloon -0.25 mm per
 * iteration) and the fronts that come from all sides into the gap between
 * the tips meet there. */
struct ShrinkWrap
{
  ForceImageType::Pointer forces;
  MeshType::Pointer       sphere;

  ShrinkWrap()
  {
    itk::EllipsoidPhantom::PointType  left, right;
    itk::EllipsoidPhantom::VectorType radii;
    radii[0] = 10.0;
    radii[1] = 8.0;
    radii[2] = 8.0;
    left[0] = 32.0 - 10.75;
    right[0] = 32.0 + 10.75;
    left[1] = right[1] = 28.0;
    left[2] = right[2] = 28.0;
    const itk::EllipsoidPhantom one(left, radii);
    const itk::EllipsoidPhantom two(right, radii);
    auto                        image = ImageType::New();
    ImageType::SizeType         size;
    size[0] = 64;
    size[1] = 56;
    size[2] = 56;
    image->SetRegions(size);
    image->Allocate();
    for (itk::ImageRegionIteratorWithIndex<ImageType> it(image, image->GetBufferedRegion()); !it.IsAtEnd(); ++it)
    {
      ImageType::PointType p;
      image->TransformIndexToPhysicalPoint(it.GetIndex(), p);
      it.Set(one.IsInside(p) || two.IsInside(p) ? 200 : 0);
    }
    auto filter = itk::ExternalForceImageFilter<ImageType, ForceImageType>::New();
    filter->SetInput(image);
    filter->SetSigma(1.0);
    filter->Update();
    forces = filter->GetOutput();
    forces->DisconnectPipeline();
    MeshType::PointType centre;
    centre[0] = 32.0;
    centre[1] = 28.0;
    centre[2] = 28.0;
    sphere = itk::MakeSphereMesh<MeshType>(centre, 23.0, 4);
  }

  FilterType::Pointer
  MakeFilter(bool prevent, double minimumDistance, unsigned int iterations) const
  {
    auto filter = FilterType::New();
    filter->SetInput(sphere);
    filter->SetForceImage(forces);
    filter->SetScaleFactor(0.5);
    filter->SetBalloon(-0.25);
    filter->SetElasticity(0.2);
    filter->SetRigidity(0.05);
    filter->SetPreventSelfIntersections(prevent);
    filter->SetMinimumDistance(minimumDistance);
    filter->SetNumberOfIterations(iterations);
    return filter;
  }
};

/** Updates \a filter, calling f() at each IterationEvent. */
template <typename TFunction>
void
ObserveIterations(FilterType * filter, TFunction f)
{
  const auto tag = filter->AddObserver(itk::IterationEvent(), [&f](const itk::EventObject &) { f(); });
  filter->Update();
  filter->RemoveObserver(tag);
}
} // namespace

TEST(SurfaceCollision, FrontsThatMeetIntersectWithoutPrevention)
{
  const ShrinkWrap      wrap;
  auto                  filter = wrap.MakeFilter(false, 0.0, 100);
  std::vector<double>   x;
  std::vector<uint32_t> triangles;
  itk::SurfaceCollision::ExtractTriangles(wrap.sphere.GetPointer(), triangles);
  itk::SizeValueType firstIteration = 0;
  std::size_t        intersecting = 0;
  ObserveIterations(filter.GetPointer(), [&] {
    if (intersecting > 0)
    {
      return;
    }
    Flatten(filter->GetOutput(), x, triangles);
    intersecting = CheckAllPairs(x, triangles, 0.0).intersecting;
    firstIteration = filter->GetCurrentIteration();
  });
  EXPECT_GT(intersecting, 0u) << "the case makes fronts cross when nothing prevents it";
  std::cout << "without prevention: " << intersecting << " intersecting pairs at iteration " << firstIteration
            << std::endl;
}

TEST(SurfaceCollision, FrontsThatMeetNeverIntersectWithPrevention)
{
  // d = 0.3 mm, about a tenth of the initial edge length (2.7 mm). Every
  // iteration's mesh: no intersecting pair, no pair of triangles sharing no
  // vertex closer than d (the constraint keeps d as computed by the
  // component; the tolerance of 1e-9 mm covers the difference in rounding
  // between its distance and this file's).
  const ShrinkWrap      wrap;
  const double          d = 0.3;
  auto                  filter = wrap.MakeFilter(true, d, 120);
  std::vector<double>   x;
  std::vector<uint32_t> triangles;
  std::size_t           iterations = 0;
  std::size_t           worstIntersecting = 0;
  double                smallest = std::numeric_limits<double>::infinity();
  itk::SizeValueType    prevented = 0;
  ObserveIterations(filter.GetPointer(), [&] {
    Flatten(filter->GetOutput(), x, triangles);
    const BruteForce check = CheckAllPairs(x, triangles, d);
    worstIntersecting = std::max(worstIntersecting, check.intersecting);
    smallest = std::min(smallest, check.smallestDistance);
    prevented += filter->GetNumberOfCollisionsPrevented();
    EXPECT_EQ(check.intersecting, 0u) << "iteration " << filter->GetCurrentIteration();
    EXPECT_GE(check.smallestDistance, d - 1e-9) << "iteration " << filter->GetCurrentIteration();
    ++iterations;
  });
  EXPECT_EQ(iterations, 120u);
  EXPECT_EQ(worstIntersecting, 0u);
  EXPECT_GE(smallest, d - 1e-9);
  EXPECT_GT(filter->GetTotalNumberOfCollisionsPrevented(), 0u) << "the constraint acted";
  EXPECT_EQ(filter->GetTotalNumberOfCollisionsPrevented(), prevented);
  std::cout << "with prevention: smallest distance " << smallest << " mm, " << prevented << " near-collisions handled"
            << std::endl;

  // The surface did wrap the objects: from radius 23 about the x axis to a
  // mean of 6.2 without prevention (ellipsoids of radius 8 across x; 5.6 at
  // the first crossing), 6.1 with it. With prevention the bottom of the
  // crease that forms over the gap stops where its two walls are d apart
  // (it stays near radius 10.6), which is the contact prevented.
  double meanRadius = 0.0;
  for (auto it = filter->GetOutput()->GetPoints()->Begin(); it != filter->GetOutput()->GetPoints()->End(); ++it)
  {
    const auto & p = it.Value();
    meanRadius += std::hypot(p[1] - 28.0, p[2] - 28.0);
  }
  meanRadius /= static_cast<double>(filter->GetOutput()->GetNumberOfPoints());
  EXPECT_LT(meanRadius, 7.0) << "the sphere shrank onto the ellipsoids";
}

TEST(SurfaceCollision, RememberedContactsAreTestedLessOften)
{
  // The shrink-wrap's crease over the gap, 160 iterations with d = 0.3 mm,
  // with and without the contact memory: every iteration free of
  // intersections and of pairs closer than d either way (the test decides
  // every step), the same wrapped surface, and with the memory fewer
  // violating pairs found: the balloon keeps pushing the crease's vertices
  // into the contact; without the memory each is proposed into it, found,
  // and halved at every iteration, with it about every other iteration
  // (342 488 pairs found without, 214 152 with; mean radius 6.140 and 6.142).
  const ShrinkWrap      wrap;
  const double          d = 0.3;
  std::vector<double>   x;
  std::vector<uint32_t> triangles;
  itk::SizeValueType    found[2] = { 0, 0 };
  double                meanRadius[2] = { 0.0, 0.0 };
  for (const bool remember : { false, true })
  {
    auto filter = wrap.MakeFilter(true, d, 160);
    filter->SetRememberContacts(remember);
    EXPECT_EQ(filter->GetRememberContacts(), remember);
    itk::SizeValueType iterations = 0;
    itk::SizeValueType reduced = 0;
    ObserveIterations(filter.GetPointer(), [&] {
      ++iterations;
      if (iterations % 4 != 0 && iterations < 150)
      {
        return; // the brute-force check at every fourth iteration and the last ten
      }
      Flatten(filter->GetOutput(), x, triangles);
      const BruteForce check = CheckAllPairs(x, triangles, d);
      EXPECT_EQ(check.intersecting, 0u) << "iteration " << filter->GetCurrentIteration() << ", memory " << remember;
      EXPECT_GE(check.smallestDistance, d - 1e-9) << "iteration " << filter->GetCurrentIteration();
      reduced = std::max(reduced, filter->GetNumberOfConstrainedVertices());
    });
    EXPECT_EQ(iterations, 160u);
    EXPECT_GT(reduced, 100u) << "the contact holds vertices";
    found[remember] = filter->GetTotalNumberOfCollisionsPrevented();
    for (auto it = filter->GetOutput()->GetPoints()->Begin(); it != filter->GetOutput()->GetPoints()->End(); ++it)
    {
      meanRadius[remember] += std::hypot(it.Value()[1] - 28.0, it.Value()[2] - 28.0);
    }
    meanRadius[remember] /= static_cast<double>(filter->GetOutput()->GetNumberOfPoints());
  }
  EXPECT_LT(4 * found[1], 3 * found[0]) << "the memory finds a quarter fewer violating pairs at least";
  EXPECT_NEAR(meanRadius[1], meanRadius[0], 0.1) << "the same wrapped surface";
  EXPECT_LT(meanRadius[1], 7.0);
  std::cout << "violating pairs found without and with the contact memory: " << found[0] << ", " << found[1]
            << "; mean radius " << meanRadius[0] << ", " << meanRadius[1] << std::endl;
}

TEST(SurfaceCollision, PreventionChangesNothingWhereNothingCollides)
{
  // The shrink-wrap's first 20 iterations, far from any contact: the same
  // bits with and without prevention, and nothing counted.
  const ShrinkWrap wrap;
  auto             off = wrap.MakeFilter(false, 0.0, 20);
  auto             on = wrap.MakeFilter(true, 0.3, 20);
  off->Update();
  on->Update();
  EXPECT_EQ(on->GetTotalNumberOfCollisionsPrevented(), 0u);
  EXPECT_EQ(on->GetNumberOfConstrainedVertices(), 0u);
  for (itk::SizeValueType i = 0; i < wrap.sphere->GetNumberOfPoints(); ++i)
  {
    ASSERT_EQ(on->GetOutput()->GetPoint(i), off->GetOutput()->GetPoint(i)) << "point " << i;
  }
  EXPECT_NE(on->GetOutput()->GetPoint(0), wrap.sphere->GetPoint(0));
}

TEST(SurfaceCollision, RejectsASelfIntersectingInputAndABadMinimumDistance)
{
  const ShrinkWrap wrap;
  // Two spheres crossing each other as one mesh.
  MeshType::PointType c1, c2;
  c1[0] = 28.0;
  c2[0] = 36.1;
  c1[1] = c2[1] = 28.0;
  c1[2] = 28.0;
  c2[2] = 28.3;
  const auto one = itk::MakeSphereMesh<MeshType>(c1, 6.0, 2);
  const auto two = itk::MakeSphereMesh<MeshType>(c2, 6.0, 2);
  auto       both = MeshType::New();
  for (auto it = one->GetPoints()->Begin(); it != one->GetPoints()->End(); ++it)
  {
    both->SetPoint(it.Index(), it.Value());
  }
  const auto offset = one->GetNumberOfPoints();
  for (auto it = two->GetPoints()->Begin(); it != two->GetPoints()->End(); ++it)
  {
    both->SetPoint(offset + it.Index(), it.Value());
  }
  itk::IdentifierType cell = 0;
  for (const auto * mesh : { one.GetPointer(), two.GetPointer() })
  {
    const auto shift = mesh == one.GetPointer() ? 0 : offset;
    for (auto it = mesh->GetCells()->Begin(); it != mesh->GetCells()->End(); ++it)
    {
      MeshType::CellAutoPointer triangle;
      triangle.TakeOwnership(new itk::TriangleCell<MeshType::CellType>);
      for (unsigned int k = 0; k < 3; ++k)
      {
        triangle->SetPointId(k, it.Value()->PointIdsBegin()[k] + shift);
      }
      both->SetCell(cell++, triangle);
    }
  }
  auto filter = wrap.MakeFilter(true, 0.0, 1);
  filter->SetInput(both);
  const std::string message = edm::test::UpdateAndGetError(filter.GetPointer());
  EXPECT_NE(message.find("intersects itself"), std::string::npos) << message;
  EXPECT_NE(message.find("the first triangles "), std::string::npos) << message;
  EXPECT_NE(message.find("cells "), std::string::npos) << message;
  // The pair named is one that intersects.
  std::vector<double>   x;
  std::vector<uint32_t> triangles;
  Flatten(both, x, triangles);
  std::pair<itk::SizeValueType, itk::SizeValueType> first;
  itk::SurfaceCollision::CountSelfIntersections(x.data(), triangles.data(), triangles.size() / 3, &first);
  EXPECT_NE(message.find("triangles " + std::to_string(first.first) + " and " + std::to_string(first.second)),
            std::string::npos)
    << message;
  // Without prevention the same input runs.
  filter->SetPreventSelfIntersections(false);
  EXPECT_EQ(edm::test::UpdateAndGetError(filter.GetPointer()), "");

  for (const double bad : { -0.1, std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::infinity() })
  {
    auto              f = wrap.MakeFilter(true, bad, 1);
    const std::string m = edm::test::UpdateAndGetError(f.GetPointer());
    EXPECT_NE(m.find("MinimumDistance"), std::string::npos) << bad << ": " << m;
  }
}

TEST(SurfaceCollision, RemeshingDuringTheShrinkWrapNeverBringsFrontsCloserThanD)
{
  // The shrink-wrap with prevention (d = 0.3 mm) and adaptive remeshing to
  // 1 mm every 10 iterations: every iteration's mesh, remeshed or not, has no
  // intersecting pair and no pair sharing no vertex closer than d (brute
  // force). Before the remeshed surface was checked, the remeshing of
  // iteration 40 brought two fronts in the crease to 0.109 mm (relaxation
  // and collapses next to the contact), and 65 of the 160 iterations had
  // pairs closer than d.
  const ShrinkWrap      wrap;
  const double          d = 0.3;
  auto                  filter = wrap.MakeFilter(true, d, 160);
  std::vector<double>   x;
  std::vector<uint32_t> triangles;
  double                smallest = std::numeric_limits<double>::infinity();
  std::size_t           worstIntersecting = 0;
  itk::SizeValueType    locked = 0;
  itk::SizeValueType    lockingRemeshings = 0;
  filter->SetRemeshingEdgeLength(1.0);
  filter->SetRemeshingInterval(10);
  ObserveIterations(filter.GetPointer(), [&] {
    Flatten(filter->GetOutput(), x, triangles);
    const BruteForce check = CheckAllPairs(x, triangles, d);
    worstIntersecting = std::max(worstIntersecting, check.intersecting);
    smallest = std::min(smallest, check.smallestDistance);
    EXPECT_EQ(check.intersecting, 0u) << "iteration " << filter->GetCurrentIteration();
    EXPECT_GE(check.smallestDistance, d - 1e-9) << "iteration " << filter->GetCurrentIteration();
    if (filter->GetCurrentIteration() % 10 == 0)
    {
      locked = std::max(locked, filter->GetNumberOfPointsLockedByRemeshing());
      lockingRemeshings += filter->GetNumberOfPointsLockedByRemeshing() > 0 ? 1 : 0;
    }
  });
  EXPECT_EQ(filter->GetNumberOfRemeshings(), 16u);
  EXPECT_EQ(worstIntersecting, 0u);
  EXPECT_GE(smallest, d - 1e-9);
  EXPECT_GT(lockingRemeshings, 0u) << "some remeshing had to leave a contact alone";
  EXPECT_GT(filter->GetOutput()->GetNumberOfPoints(), 1026u) << "the surface was refined toward 1 mm";
  std::cout << "with remeshing: smallest distance " << smallest << " mm, " << lockingRemeshings
            << " remeshings locked points (at most " << locked << "), " << filter->GetOutput()->GetNumberOfPoints()
            << " points at the end" << std::endl;
}

TEST(SurfaceCollision, TheFilterCarriesItsCertificateThroughItsRings)
{
  // The shrink-wrap's first 60 iterations, deflating slowly (balloon -0.03
  // mm per iteration), with MinimumDistance 0 and remeshing to the initial
  // edge length (2.7 mm) every 10 iterations: the surface stays star-shaped
  // from its centroid, the certificate carries from step to step (at -0.25
  // mm an iteration the points leave its margin at once: 1 step carried of
  // 66), and after each remeshing the filter's rings lead to
  // the triangles of the points beyond the carried margin, some of them
  // cleared by their own margins. No intersecting pair at any iteration
  // (brute force).
  const ShrinkWrap      wrap;
  auto                  filter = wrap.MakeFilter(true, 0.0, 60);
  std::vector<double>   x;
  std::vector<uint32_t> triangles;
  std::size_t           worstIntersecting = 0;
  filter->SetBalloon(-0.03);
  filter->SetRemeshingEdgeLength(2.7);
  filter->SetRemeshingInterval(10);
  ObserveIterations(filter.GetPointer(), [&] {
    Flatten(filter->GetOutput(), x, triangles);
    const std::size_t intersecting = CheckAllPairs(x, triangles, 0.0).intersecting;
    worstIntersecting = std::max(worstIntersecting, intersecting);
    EXPECT_EQ(intersecting, 0u) << "iteration " << filter->GetCurrentIteration();
  });
  std::cout << filter->GetNumberOfCertifiedSteps() << " steps certified, " << filter->GetNumberOfCarriedCertificates()
            << " carried, " << filter->GetNumberOfPointsWithinOwnCarriedMargin()
            << " points cleared by their own margins, " << filter->GetNumberOfCollisionIndexRebuilds()
            << " index builds" << std::endl;
  EXPECT_EQ(filter->GetNumberOfRemeshings(), 6u);
  EXPECT_EQ(worstIntersecting, 0u);
  EXPECT_GT(filter->GetNumberOfCarriedCertificates(), 0u);
  EXPECT_GT(filter->GetNumberOfPointsWithinOwnCarriedMargin(), 0u);
}

TEST(SurfaceCollision, ASurfaceHeldAgainstItselfConverges)
{
  // The shrink-wrap with prevention (d = 0.3 mm) rests in the crease over
  // the gap while the balloon keeps pushing about 400 vertices there into
  // the contact, which holds them. The convergence test must measure the
  // displacements made, not those proposed: before it did, the run with
  // ConvergenceFraction 0.005 never converged (1 500 iterations, 408 vertices
  // counted active while the largest displacement made was 0.0002 mm), nor
  // the one along the normals. Without prevention both converge (about 350
  // iterations, no contact held).
  const ShrinkWrap wrap;
  for (const bool alongNormals : { false, true })
  {
    auto filter = wrap.MakeFilter(true, 0.3, 1500);
    filter->SetConvergenceTolerance(0.02);
    filter->SetConvergenceWindow(3);
    filter->SetConvergenceFraction(alongNormals ? 0.0 : 0.005);
    filter->SetConvergenceAlongNormals(alongNormals);
    filter->Update();
    EXPECT_TRUE(filter->GetConverged()) << (alongNormals ? "along the normals" : "fraction 0.005");
    EXPECT_LT(filter->GetCurrentIteration(), 300u) << (alongNormals ? "along the normals" : "fraction 0.005");
    EXPECT_GT(filter->GetNumberOfConstrainedVertices(), 100u) << "the contact holds vertices at the end";
    if (!alongNormals)
    {
      EXPECT_LE(filter->GetNumberOfActiveVertices(), 0.005 * filter->GetOutput()->GetNumberOfPoints());
    }
    std::cout << (alongNormals ? "along the normals: " : "fraction 0.005: ") << filter->GetCurrentIteration()
              << " iterations, " << filter->GetNumberOfActiveVertices() << " active, "
              << filter->GetNumberOfConstrainedVertices() << " held by the contact" << std::endl;
  }
}
