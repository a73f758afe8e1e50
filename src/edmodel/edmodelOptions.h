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
#ifndef edmodelOptions_h
#define edmodelOptions_h

// Plain C++ (no ITK header): the options of each subcommand, their defaults
// and the error type that carries an exit code.

#include <stdexcept>
#include <string>

namespace edm
{

/** The defaults the command line shares with the core filters, read from a
 * default-constructed itk::ExternalForceImageFilter and
 * itk::DeformableMeshFilter (edmodelPipeline.cxx): the core stays their
 * single source of truth. */
struct CoreDefaults
{
  bool         NormalizeForces;
  bool         GradientVectorFlow;
  double       GradientVectorFlowRegularization;
  unsigned int GradientVectorFlowIterations;
  bool         TangentialElasticity;
  double       Balloon;
  double       MaximumStepLength;
  unsigned int ConvergenceWindow;
  double       IntensityTolerance;
};
const CoreDefaults &
GetCoreDefaults();

/** The defaults of the command line that differ from the core's (the core's
 * are neutral: no elasticity, no iteration, no convergence test) or have no
 * counterpart there. Lengths are in physical units (mm for medical images). */
namespace defaults
{
/** Gaussian smoothing of the force field, in voxels of the smallest spacing
 * (so 1 mm on the seed's 1 mm grid). */
constexpr double SigmaInVoxels = 1.0;
/** Largest external displacement per iteration, as a fraction of Sigma. */
constexpr double ScaleOverSigma = 0.5;
constexpr double Elasticity = 0.3;
/** The full umbrella operator (not only its tangential part, the core's
 * default): with the region force, the normal part is what keeps the
 * surface from folding into dark pockets (ventricles, sulci). */
constexpr bool TangentialElasticity = false;
/** On 2-D contours, the tangential part only (the core's default): along a
 * chain of points the normal part of the umbrella operator pulls a convex
 * contour inward by about a h^2 kappa / 2 per iteration against the image
 * forces, and damps the mode of points alternating across the curve by 2a
 * (about 1.5a on a triangle mesh), so that without the oscillation damping
 * the capture level never converged. With it, the full umbrella converges
 * but ends farther from the true curve on every shape of the tests and of
 * bench/compare-skimage.py (ellipse 0.085 / 0.139 pixel against 0.074 /
 * 0.118, star 0.067 / 0.30 against 0.058 / 0.23). Rigidity still smooths. */
constexpr bool         ContourTangentialElasticity = true;
constexpr double       Rigidity = 0.05;
constexpr unsigned int Iterations = 500;
/** Iteration cap of the capture level (the first of several coarse-to-fine
 * levels) when --iterations is lower. */
constexpr unsigned int CaptureIterations = 2000;
constexpr double       ConvergenceTolerance = 0.02;
/** A level is quiet when at most this fraction of its vertices move by the
 * tolerance or more (the filter's ConvergenceFraction). */
constexpr double ConvergenceFraction = 0.005;
/** The collision test (the filter's PreventSelfIntersections) is on by
 * default for 3-D surfaces (--allow-self-intersections turns it off): no
 * step leaves two triangles sharing no vertex intersecting or closer than
 * MinimumDistanceOverEdgeLength times --edge-length (0.05 mm on a 1 mm grid).
 * Without it, 16 of the 26 runs of bench/robustness.sh end with a surface
 * that intersects itself (ch2bet with the defaults: 70 pairs of triangles;
 * with --sigma 2: 5 879); with it none does, and every Dice is within
 * 0.008 of the defaults' (2026-12-07; without it, 2026-12-05: within 0.014).
 * It costs time: on ch2bet from the validation's sphere 7 to 8 s against
 * 2.7 to 2.9 s, and where a wide contact holds thousands of points at
 * every iteration (ch2bet with --sigma 2) about a minute (docs/performance.md).
 * With a distance of 0 the fronts that meet in the interhemispheric fissure
 * are pressed onto each other (smallest angle 0.13 degrees, 24 triangles
 * under 1 degree); 0.05 keeps them open (2.57 degrees; 0.1: 3.57 degrees, a
 * third slower), the Dice and mean distance the same to 4 digits. */
constexpr bool   PreventSelfIntersections = true;
constexpr double MinimumDistanceOverEdgeLength = 0.05;
/** Subdivisions of the octahedron of --init-sphere (4 * 4^n + 2 points). */
constexpr unsigned int SphereResolution = 4;
/** Radius of the default initial sphere, as a fraction of the smallest
 * physical extent of the image. */
constexpr double       SphereRadiusOverExtent = 0.25;
constexpr unsigned int SnapshotEvery = 10;
/** Points of the initial circle of --init-circle (2-D): the coarse level of
 * the contour, refined like the sphere (each edge split in two) until its
 * mean edge is about --edge-length. */
constexpr unsigned int CirclePoints = 64;
/** Region force: largest inflation or deflation per iteration, as a fraction
 * of the smallest voxel spacing, and the smoothing of its image in voxels. */
constexpr double RegionWeightInVoxels = 0.25;
constexpr double RegionSigmaInVoxels = 1.0;
/** Edge search: largest displacement per iteration toward the edge found
 * along the normal, and how far it looks on each side, in voxels of the
 * smallest spacing. */
constexpr double EdgeSearchWeightInVoxels = 0.0;
constexpr double EdgeSearchDistanceInVoxels = 2.0;
/** Mean edge length the coarse-to-fine refinement aims at, in voxels of the
 * smallest spacing, and the largest number of points it creates. */
constexpr double       EdgeLengthInVoxels = 1.0;
constexpr unsigned int MaximumRefinedPoints = 2000000;
/** Levels whose mean edge is below this many --edge-length have their
 * region weight scaled by the square of the ratio (edmodelPipeline.cxx). */
constexpr double FineLevelEdgeLengths = 2.0;
/** The first level's region force sees the image smoothed this many times
 * more than the later ones. */
constexpr double CoarseRegionSigmaFactor = 2.0;
/** On 2-D contours the capture level's region force is four times as fast
 * (one voxel per iteration; the transition width grows with the weight, so
 * that the speed near the boundary is the same) and sees the image smoothed
 * as the later levels do. On the ellipse, rotated ellipse and star of
 * bench/compare-skimage.py the capture then takes 33 to 40 iterations (59
 * to 68 with the factor 2, 108 to 120 with 1; 25 with 8), the image is
 * smoothed once for the force field and the region force, and the final
 * contours are as close to the true curves (mean 0.038 to 0.054 pixel with
 * the factors 2, 4 and 8). On nine axial slices of ch2bet the factor 4
 * against 2 gave the same distances to the brain's boundary (one slice
 * better: a leak of the factor 2), the factor 8 hit the iteration cap on
 * one. On 3-D surfaces the faster capture (factor 2) gained no time and
 * lowered ch2bet's Dice (0.9842 to 0.9830): surfaces keep the factors 1 and
 * CoarseRegionSigmaFactor. */
constexpr double ContourCaptureRegionWeightFactor = 4.0;
constexpr double ContourCaptureRegionSigmaFactor = 1.0;
/** Closed contours pushed outward are checked every this many iterations
 * for edges that cross (edmodelContour.cxx: the level then stops, the
 * contour loses its loops, is resampled and the level starts again), at
 * most ContourMaximumRestarts times in a run; the capture level is also
 * resampled when its longest edge exceeds ContourCaptureStretch times the
 * initial contour's mean edge. On the synthetic shapes of
 * bench/compare-skimage.py no edge crosses and the capture's longest edge
 * stays below 5.2 times the initial mean edge (the star's, at iteration 30;
 * 3.4 on the ellipses at the end). */
constexpr unsigned int ContourCheckInterval = 10;
constexpr double       ContourCaptureStretch = 6.0;
constexpr unsigned int ContourMaximumRestarts = 100;
/** The demo adds gradient vector flow to the segment defaults: the seed's
 * sphere starts 12 voxels from the ends of the ellipsoid, beyond the capture
 * range of the plain gradient force at sigma = 1 voxel. */
constexpr bool DemoGradientVectorFlow = true;
/** Accuracy the demo must reach to exit with 0: mean and largest distance of
 * the final mesh to the true ellipsoid, in voxels (half a voxel is where a
 * binary image places its boundary). */
constexpr double DemoMeanDistanceLimit = 0.5;
constexpr double DemoMaximumDistanceLimit = 1.5;
} // namespace defaults

/** Exit codes. */
constexpr int ExitSuccess = 0;
constexpr int ExitFailure = 1; // the run completed but its result is poor, or an internal error
constexpr int ExitUsage = 2;   // bad command line or bad input: nothing was written

/** An error reported as one line on stderr, with its exit code. */
class Error : public std::runtime_error
{
public:
  explicit Error(const std::string & message, int exitCode = ExitUsage)
    : std::runtime_error(message)
    , m_ExitCode(exitCode)
  {}
  int
  GetExitCode() const
  {
    return m_ExitCode;
  }

private:
  int m_ExitCode;
};

/** Options shared by every subcommand. */
struct GlobalOptions
{
  unsigned int threads{ 0 }; // 0: ITK's default
  bool         quiet{ false };
};

struct SegmentOptions
{
  std::string  image;
  std::string  output;
  std::string  initMesh;
  std::string  forceOutput;
  std::string  snapshots;
  bool         dampOscillations{ true };
  bool         hasInitSphere{ false };
  double       sphere[4]{ 0.0, 0.0, 0.0, 0.0 }; // centre x, y, z and radius
  unsigned int sphereResolution{ defaults::SphereResolution };
  // 2-D images (edmodelContour.cxx).
  bool         hasInitCircle{ false };
  double       circle[3]{ 0.0, 0.0, 0.0 }; // centre x, y and radius
  unsigned int circlePoints{ defaults::CirclePoints };
  std::string  initContour;
  bool         openContour{ false };
  std::string  overlayPng;
  bool         fixedBoundary{ false };

  double       sigma{ -1.0 }; // negative: defaults::SigmaInVoxels times the smallest spacing
  double       scale{ -1.0 }; // negative: defaults::ScaleOverSigma times sigma
  bool         normalizeForces{ GetCoreDefaults().NormalizeForces };
  bool         gradientVectorFlow{ GetCoreDefaults().GradientVectorFlow };
  double       gradientVectorFlowRegularization{ GetCoreDefaults().GradientVectorFlowRegularization };
  unsigned int gradientVectorFlowIterations{ GetCoreDefaults().GradientVectorFlowIterations };

  double elasticity{ defaults::Elasticity };
  bool   tangentialElasticity{ defaults::TangentialElasticity };
  bool   tangentialElasticityGiven{ false }; // 2-D contours default to tangential (edmodelContour.cxx)
  double rigidity{ defaults::Rigidity };
  double balloon{ GetCoreDefaults().Balloon };
  double regionWeight{ -1.0 }; // negative: defaults::RegionWeightInVoxels times the smallest spacing
  bool   preventSelfIntersections{ defaults::PreventSelfIntersections };
  bool   preventSelfIntersectionsGiven{ false }; // 2-D contours: only an explicit --prevent-self-intersections
  double minimumDistance{ -1.0 };    // negative: defaults::MinimumDistanceOverEdgeLength times the edge length
  double edgeSearchWeight{ -1.0 };   // negative: defaults::EdgeSearchWeightInVoxels times the smallest spacing
  double edgeSearchDistance{ -1.0 }; // non-positive: defaults::EdgeSearchDistanceInVoxels times the smallest spacing
  double regionSigma{ -1.0 };        // negative: defaults::RegionSigmaInVoxels times the smallest spacing
  double intensityTolerance{ GetCoreDefaults().IntensityTolerance };
  double edgeLength{ -1.0 }; // non-positive: defaults::EdgeLengthInVoxels times the smallest spacing
  bool   hasObjectRange{ false };
  double objectRange[2]{ 0.0, 0.0 };
  double maximumStepLength{ GetCoreDefaults().MaximumStepLength };
  unsigned int iterations{ defaults::Iterations };
  double       convergenceTolerance{ defaults::ConvergenceTolerance };
  unsigned int convergenceWindow{ GetCoreDefaults().ConvergenceWindow };
  double       convergenceFraction{ defaults::ConvergenceFraction };
  unsigned int snapshotEvery{ defaults::SnapshotEvery };
  bool         snapshotEverySet{ false };
  unsigned int repeat{ 1 }; // --repeat: the computation run this many times, for timing
};

struct DemoOptions
{
  std::string outputDirectory{ "edmodel-demo" };
};

/** Subcommands, implemented in edmodelPipeline.cxx. They throw Error. */
int
RunSegment(const SegmentOptions & options, const GlobalOptions & global);
int
RunDemo(const DemoOptions & options, const GlobalOptions & global);
/** 'segment' on a 2-D image: a contour (edmodelContour.cxx). */
int
RunSegmentContour(const SegmentOptions & options, const GlobalOptions & global);

/** Applies --threads to ITK's threaders (before any filter is created). */
void
SetNumberOfThreads(unsigned int threads);

/** "ITK 5.2.1" and whether VTK outputs are available. */
std::string
GetLibraryVersions();

/** True when mesh formats that need VTK (.vtp, .stl, .pvd) can be written. */
bool
HasVTK();

} // namespace edm

#endif
