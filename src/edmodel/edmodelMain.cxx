
// edmodel: command-line face of the ExplicitDeformableModel filters.
// This file parses the command line and prints the help; the ITK pipeline is
// in edmodelPipeline.cxx, image and mesh files in edmodelIO.cxx.

#include "edmodelIO.h"
#include "edmodelOptions.h"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <functional>
#include <iostream>
#include <sstream>
#include <vector>

#ifndef EDM_VERSION
#  define EDM_VERSION "unknown"
#endif

namespace edm
{
namespace
{

std::string
FormatNumber(double value)
{
  std::ostringstream stream;
  stream << value;
  return stream.str();
}

double
ParseDouble(const std::string & option, const std::string & text)
{
  const char * begin = text.c_str();
  char *       end = nullptr;
  errno = 0;
  const double value = std::strtod(begin, &end);
  if (text.empty() || end == begin || *end != '\0' || errno == ERANGE || !std::isfinite(value))
  {
    throw Error(option + ": '" + text + "' is not a number");
  }
  return value;
}

unsigned int
ParseUnsigned(const std::string & option, const std::string & text)
{
  const char * begin = text.c_str();
  char *       end = nullptr;
  errno = 0;
  const long long value = std::strtoll(begin, &end, 10);
  if (text.empty() || end == begin || *end != '\0' || (errno == ERANGE && value < 0) || value < 0)
  {
    throw Error(option + ": '" + text + "' is not a non-negative integer");
  }
  if (errno == ERANGE || value > 1000000000LL)
  {
    throw Error(option + ": " + text + " is too large (at most 1000000000)");
  }
  return static_cast<unsigned int>(value);
}

/** Comma-separated list of exactly \a count numbers. */
std::vector<double>
ParseList(const std::string & option, const std::string & text, size_t count, const std::string & form)
{
  std::vector<double> values;
  std::string         item;
  std::istringstream  stream(text);
  try
  {
    while (std::getline(stream, item, ','))
    {
      values.push_back(ParseDouble(option, item));
    }
  }
  catch (const Error &)
  {
    throw Error(option + ": '" + text + "' is not a list of numbers " + form);
  }
  if (values.size() != count || (!text.empty() && text.back() == ','))
  {
    throw Error(option + ": expected " + std::to_string(count) + " comma-separated numbers " + form + ", got '" + text +
                "'");
  }
  return values;
}

void
RequireInRange(const std::string & option, double value, double low, double high)
{
  if (!(value >= low && value <= high))
  {
    throw Error(option + " must be in [" + FormatNumber(low) + ", " + FormatNumber(high) + "], got " +
                FormatNumber(value));
  }
}

void
RequireAtLeast(const std::string & option, double value, double low)
{
  if (!(value >= low))
  {
    throw Error(option + " must be at least " + FormatNumber(low) + ", got " + FormatNumber(value));
  }
}

/** One command-line option: its name, the name of its argument (empty for a
 * flag), its help (meaning and units), its default, and what it sets. */
struct Option
{
  std::string                              section;
  std::string                              name;
  std::string                              argument;
  std::string                              help;
  std::string                              defaultText;
  std::function<void(const std::string &)> apply;
};

using OptionTable = std::vector<Option>;

void
AddGlobalOptions(OptionTable & table, GlobalOptions & global, const std::string & section)
{
  table.push_back({ section,
                    "--threads",
                    "N",
                    "number of threads used by the filters",
                    "all cores",
                    [&global](const std::string & text) {
                      global.threads = ParseUnsigned("--threads", text);
                      RequireAtLeast("--threads", global.threads, 1);
                    } });
  table.push_back({ section,
                    "--quiet",
                    "",
                    "no progress and no summary (errors are still reported on stderr)",
                    "",
                    [&global](const std::string &) { global.quiet = true; } });
}

OptionTable
MakeSegmentOptions(SegmentOptions & o, GlobalOptions & global)
{
  OptionTable       t;
  const std::string io = "Input and output";
  t.push_back(
    { io,
      "--image",
      "PATH",
      "image to segment: a 3-D image, any file ITK reads (.nii, .nii.gz, .nrrd, .nhdr, .mha, .mhd, ...) or a "
      "directory holding a DICOM series; or a 2-D image (.png, .tif, 2-D .nii, .nrrd, .mha, or a volume of one "
      "slice), segmented with a contour (see '2-D images' above); any intensity range; required",
      "",
      [&o](const std::string & s) { o.image = s; } });
  t.push_back({ io,
                "--output",
                "MESH",
                "deformed mesh, format chosen by extension: .vtk (legacy VTK), .obj, .off, .gii" +
                  std::string(HasVTK() ? ", .vtp, .stl" : " (.vtp and .stl need a build with VTK)") +
                  "; of a 2-D image, the contour: .vtk or .vtp (polylines) or .csv (x,y per point); coordinates in "
                  "the image's physical frame (mm); required",
                "",
                [&o](const std::string & s) { o.output = s; } });
  t.push_back(
    { io,
      "--init-sphere",
      "X,Y,Z,R",
      "initial surface: a sphere of centre (X,Y,Z) and radius R in physical coordinates (mm); it must lie "
      "inside the image",
      "centred in the image, radius " + FormatNumber(defaults::SphereRadiusOverExtent) + " x the smallest extent",
      [&o](const std::string & s) {
        const auto v = ParseList("--init-sphere", s, 4, "X,Y,Z,R");
        for (unsigned int k = 0; k < 4; ++k)
        {
          o.sphere[k] = v[k];
        }
        if (!(v[3] > 0.0))
        {
          throw Error("--init-sphere: the radius must be positive, got " + FormatNumber(v[3]));
        }
        o.hasInitSphere = true;
      } });
  t.push_back({ io,
                "--sphere-resolution",
                "N",
                "subdivisions of the octahedron of the initial sphere (4 x 4^N + 2 points), 0 to 7",
                std::to_string(defaults::SphereResolution),
                [&o](const std::string & s) {
                  o.sphereResolution = ParseUnsigned("--sphere-resolution", s);
                  RequireInRange("--sphere-resolution", o.sphereResolution, 0, 7);
                } });
  t.push_back({ io,
                "--init-mesh",
                "MESH",
                "initial surface: a triangle mesh (.vtk, .obj, .off, .gii, ...) in physical coordinates; instead of "
                "--init-sphere",
                "",
                [&o](const std::string & s) { o.initMesh = s; } });
  t.push_back(
    { io,
      "--init-circle",
      "X,Y,R",
      "2-D image: initial contour, a circle of centre (X,Y) and radius R in physical coordinates (mm), "
      "inside the object; it must lie inside the image",
      "centred in the image, radius " + FormatNumber(defaults::SphereRadiusOverExtent) + " x the smallest extent",
      [&o](const std::string & s) {
        const auto v = ParseList("--init-circle", s, 3, "X,Y,R");
        for (unsigned int k = 0; k < 3; ++k)
        {
          o.circle[k] = v[k];
        }
        if (!(v[2] > 0.0))
        {
          throw Error("--init-circle: the radius must be positive, got " + FormatNumber(v[2]));
        }
        o.hasInitCircle = true;
      } });
  t.push_back({ io,
                "--circle-points",
                "N",
                "2-D image: points of the initial circle, 8 to 100000 (refined until the mean edge is about "
                "--edge-length)",
                std::to_string(defaults::CirclePoints),
                [&o](const std::string & s) {
                  o.circlePoints = ParseUnsigned("--circle-points", s);
                  RequireInRange("--circle-points", o.circlePoints, 8, 100000);
                } });
  t.push_back({ io,
                "--init-contour",
                "FILE",
                "2-D image: initial contour(s) in physical coordinates (mm), instead of --init-circle: a .csv of x,y "
                "points, one per line (a first line that is not numbers is a header, an empty line starts another "
                "contour; closed unless --open), or the polylines and polygons of a .vtk" +
                  std::string(HasVTK() ? " or .vtp" : "") +
                  " (a polyline that ends on its first point is closed; z ignored)",
                "",
                [&o](const std::string & s) { o.initContour = s; } });
  t.push_back({ io,
                "--open",
                "",
                "the contours of the --init-contour .csv are open (the region force and the balloon then stay off: "
                "outward is undefined)",
                "closed",
                [&o](const std::string &) { o.openContour = true; } });
  t.push_back({ io,
                "--fixed-boundary",
                "",
                "the ends of open contours and the boundary of open surfaces keep their initial position",
                "off (they move)",
                [&o](const std::string &) { o.fixedBoundary = true; } });
  t.push_back({ io,
                "--overlay-png",
                "PNG",
                "2-D image: also draw the initial (yellow) and final (red) contours over the image, in a PNG (the "
                "image's intensities from its 0.5th to 99.5th percentile in grey, pixels shown with their aspect "
                "ratio, enlarged to at least 512 pixels across)",
                "",
                [&o](const std::string & s) { o.overlayPng = s; } });
  t.push_back({ io,
                "--force-output",
                "IMG",
                "also write the external force field (vector image of 3 components, 2 for a 2-D image, e.g. .mha, "
                ".nrrd, .nii.gz)",
                "",
                [&o](const std::string & s) { o.forceOutput = s; } });
  t.push_back({ io,
                "--snapshots",
                "DIR",
                "write the mesh every K iterations and a ParaView .pvd time series into DIR (needs a build with VTK); "
                "the series appears when the run succeeds (an interrupted or failed run leaves none of its files) and "
                "replaces an earlier series of the same name in DIR",
                "",
                [&o](const std::string & s) { o.snapshots = s; } });
  t.push_back({ io,
                "--every",
                "K",
                "iterations between two snapshots (with --snapshots)",
                std::to_string(defaults::SnapshotEvery),
                [&o](const std::string & s) {
                  o.snapshotEvery = ParseUnsigned("--every", s);
                  RequireAtLeast("--every", o.snapshotEvery, 1);
                  o.snapshotEverySet = true;
                } });
  t.push_back({ io,
                "--repeat",
                "N",
                "for timing: compute the force field and the deformation N times in this process and report the "
                "fastest run and the first (the result, the same each time, is written once)",
                "1",
                [&o](const std::string & s) {
                  o.repeat = ParseUnsigned("--repeat", s);
                  RequireAtLeast("--repeat", o.repeat, 1);
                } });

  const std::string force =
    "External force field (ExternalForceImageFilter): gradient of |gradient of the smoothed image|";
  t.push_back({ force,
                "--sigma",
                "MM",
                "standard deviation of the Gaussian smoothing, physical units (mm); sets the capture range (about 2 to "
                "3 sigma on each side of an edge); 0 disables smoothing",
                FormatNumber(defaults::SigmaInVoxels) + " x the smallest voxel spacing",
                [&o](const std::string & s) {
                  o.sigma = ParseDouble("--sigma", s);
                  RequireAtLeast("--sigma", o.sigma, 0.0);
                } });
  t.push_back({ force,
                "--no-normalize-forces",
                "",
                "keep the raw force field (intensity / mm^2) instead of dividing it by its largest length; --scale "
                "is then no longer in mm (consider --max-step)",
                GetCoreDefaults().NormalizeForces ? "normalised" : "raw",
                [&o](const std::string &) { o.normalizeForces = false; } });
  t.push_back({ force,
                "--gvf",
                "",
                "diffuse the force by gradient vector flow (Xu and Prince): larger capture range, reaches into "
                "concavities",
                GetCoreDefaults().GradientVectorFlow ? "on" : "off",
                [&o](const std::string &) { o.gradientVectorFlow = true; } });
  t.push_back({ force,
                "--gvf-mu",
                "MU",
                "regularisation weight of gradient vector flow (dimensionless, > 0): larger is smoother and reaches "
                "farther",
                FormatNumber(GetCoreDefaults().GradientVectorFlowRegularization),
                [&o](const std::string & s) {
                  o.gradientVectorFlowRegularization = ParseDouble("--gvf-mu", s);
                  if (!(o.gradientVectorFlowRegularization > 0.0))
                  {
                    throw Error("--gvf-mu must be positive, got " + FormatNumber(o.gradientVectorFlowRegularization));
                  }
                } });
  t.push_back(
    { force,
      "--gvf-iterations",
      "N",
      "diffusion iterations of gradient vector flow (the field spreads as the square root of N)",
      std::to_string(GetCoreDefaults().GradientVectorFlowIterations),
      [&o](const std::string & s) { o.gradientVectorFlowIterations = ParseUnsigned("--gvf-iterations", s); } });

  const std::string model = "Deformable model (DeformableMeshFilter)";
  t.push_back({ model,
                "--scale",
                "MM",
                "weight of the external force: with normalised forces, the largest external displacement per "
                "iteration, physical units (mm)",
                FormatNumber(defaults::ScaleOverSigma) + " x sigma",
                [&o](const std::string & s) {
                  o.scale = ParseDouble("--scale", s);
                  RequireAtLeast("--scale", o.scale, 0.0);
                } });
  t.push_back({ model,
                "--elasticity",
                "A",
                "weight of the elastic (membrane) force pulling each vertex toward the centroid of its neighbours, "
                "dimensionless in [0, 1]; with the coarse-to-fine schedule it sets the refined levels (the first, "
                "capture level keeps the default)",
                FormatNumber(defaults::Elasticity),
                [&o](const std::string & s) {
                  o.elasticity = ParseDouble("--elasticity", s);
                  RequireInRange("--elasticity", o.elasticity, 0.0, 1.0);
                } });
  const std::string collisionDefault =
    std::string(defaults::PreventSelfIntersections ? "on" : "off") + " for 3-D surfaces (not used on 2-D contours)";
  t.push_back({ model,
                "--prevent-self-intersections",
                "",
                "no step lets the surface intersect itself or bring two triangles sharing no vertex closer than "
                "--minimum-distance: the displacements of the vertices of colliding triangles are halved, then "
                "zeroed; an --init-mesh that intersects itself is an error (3-D surfaces only; slower, much slower "
                "where the surface is pressed against itself over a wide area)",
                collisionDefault,
                [&o](const std::string &) {
                  o.preventSelfIntersections = true;
                  o.preventSelfIntersectionsGiven = true;
                } });
  t.push_back({ model,
                "--allow-self-intersections",
                "",
                "turn the collision test of --prevent-self-intersections off: faster (about a third of the time on "
                "a brain), but parts of the surface may pass through each other where they meet",
                "the test is " + collisionDefault,
                [&o](const std::string &) {
                  o.preventSelfIntersections = false;
                  o.preventSelfIntersectionsGiven = true;
                } });
  t.push_back({ model,
                "--minimum-distance",
                "MM",
                "with the collision test (--prevent-self-intersections), the smallest distance a step may leave "
                "between two triangles "
                "sharing no vertex, physical units (mm); 0 only keeps them from intersecting; keep it below half "
                "the shortest edge",
                FormatNumber(defaults::MinimumDistanceOverEdgeLength) + " x --edge-length",
                [&o](const std::string & s) {
                  o.minimumDistance = ParseDouble("--minimum-distance", s);
                  RequireAtLeast("--minimum-distance", o.minimumDistance, 0.0);
                } });
  t.push_back({ model,
                "--tangential-elasticity",
                "",
                "keep only the component of the elastic force tangent to the surface (it then spaces the vertices "
                "evenly but no longer smooths the surface's shape)",
                std::string(defaults::TangentialElasticity ? "tangential" : "full umbrella (smooths the shape)") +
                  " on 3-D surfaces, " + (defaults::ContourTangentialElasticity ? "tangential" : "full umbrella") +
                  " on 2-D contours",
                [&o](const std::string &) {
                  o.tangentialElasticity = true;
                  o.tangentialElasticityGiven = true;
                } });
  t.push_back({ model,
                "--no-tangential-elasticity",
                "",
                "use the full umbrella operator (Laplacian smoothing: smooths the surface and keeps it from folding; "
                "shrinks convex surfaces slightly, which the region force balances)",
                std::string(defaults::TangentialElasticity ? "tangential" : "full umbrella") + " on 3-D surfaces, " +
                  (defaults::ContourTangentialElasticity ? "tangential" : "full umbrella") + " on 2-D contours",
                [&o](const std::string &) {
                  o.tangentialElasticity = false;
                  o.tangentialElasticityGiven = true;
                } });
  t.push_back({ model,
                "--rigidity",
                "B",
                "weight of the rigidity (bending) force, the umbrella operator applied twice, dimensionless in [0, 1] "
                "(elasticity + 2 x rigidity above 1 is scaled down to 1); like --elasticity, it sets the refined "
                "levels of the coarse-to-fine schedule",
                FormatNumber(defaults::Rigidity),
                [&o](const std::string & s) {
                  o.rigidity = ParseDouble("--rigidity", s);
                  RequireInRange("--rigidity", o.rigidity, 0.0, 1.0);
                } });
  t.push_back({ model,
                "--balloon",
                "MM",
                "inflation along the outward normal per iteration, physical units (mm); negative deflates",
                FormatNumber(GetCoreDefaults().Balloon),
                [&o](const std::string & s) { o.balloon = ParseDouble("--balloon", s); } });
  t.push_back({ model,
                "--region",
                "MM",
                "weight of the region force: largest inflation (inside the object's intensity range) or deflation "
                "(outside it) per iteration, physical units (mm); stops by itself on the object's boundary; 0 turns "
                "it off",
                FormatNumber(defaults::RegionWeightInVoxels) + " x the smallest voxel spacing",
                [&o](const std::string & s) {
                  o.regionWeight = ParseDouble("--region", s);
                  RequireAtLeast("--region", o.regionWeight, 0.0);
                } });
  t.push_back({ model,
                "--edge-search",
                "MM",
                "weight of the edge search: largest displacement per iteration toward the strongest edge of the "
                "object's polarity found along the normal within --edge-search-distance (median of the vertex's and "
                "its neighbours' hits), physical units (mm); 0 turns it off",
                FormatNumber(defaults::EdgeSearchWeightInVoxels) + " x the smallest voxel spacing",
                [&o](const std::string & s) {
                  o.edgeSearchWeight = ParseDouble("--edge-search", s);
                  RequireAtLeast("--edge-search", o.edgeSearchWeight, 0.0);
                } });
  t.push_back({ model,
                "--edge-search-distance",
                "MM",
                "how far the edge search looks on each side of the surface along the normal, physical units (mm)",
                FormatNumber(defaults::EdgeSearchDistanceInVoxels) + " x the smallest voxel spacing",
                [&o](const std::string & s) {
                  o.edgeSearchDistance = ParseDouble("--edge-search-distance", s);
                  if (!(o.edgeSearchDistance > 0.0 && std::isfinite(o.edgeSearchDistance)))
                  {
                    throw Error("--edge-search-distance must be positive and finite, got " + s);
                  }
                } });
  t.push_back({ model,
                "--edge-length",
                "MM",
                "mean edge length the surface is refined to: it converges at its initial resolution, then each "
                "triangle is split into four and it converges again, until its mean edge is at most 1.5 x MM, "
                "physical units (mm)",
                FormatNumber(defaults::EdgeLengthInVoxels) + " x the smallest voxel spacing",
                [&o](const std::string & s) {
                  o.edgeLength = ParseDouble("--edge-length", s);
                  if (!(o.edgeLength > 0.0 && std::isfinite(o.edgeLength)))
                  {
                    throw Error("--edge-length must be positive and finite, got " + s);
                  }
                } });
  t.push_back({ model,
                "--region-sigma",
                "MM",
                "Gaussian smoothing of the image for the region force, physical units (mm)",
                FormatNumber(defaults::RegionSigmaInVoxels) + " x the smallest voxel spacing",
                [&o](const std::string & s) {
                  o.regionSigma = ParseDouble("--region-sigma", s);
                  RequireAtLeast("--region-sigma", o.regionSigma, 0.0);
                } });
  t.push_back({ model,
                "--intensity-tolerance",
                "K",
                "half-width of the object's intensity class, estimated inside the initial surface, in robust "
                "standard deviations (> 0); the range's bounds then move halfway to the background's intensity "
                "once the surface reaches it (sampled 1 to 4 voxels outside)",
                FormatNumber(GetCoreDefaults().IntensityTolerance),
                [&o](const std::string & s) {
                  o.intensityTolerance = ParseDouble("--intensity-tolerance", s);
                  if (!(o.intensityTolerance > 0.0))
                  {
                    throw Error("--intensity-tolerance must be positive, got " + FormatNumber(o.intensityTolerance));
                  }
                } });
  t.push_back({ model,
                "--object-range",
                "LO,HI",
                "the object's intensity range for the region force, in image units, instead of the estimate "
                "(fixed: no background estimate)",
                "estimated inside the initial surface",
                [&o](const std::string & s) {
                  const auto v = ParseList("--object-range", s, 2, "LO,HI");
                  if (!(v[0] < v[1]))
                  {
                    throw Error("--object-range: LO must be below HI, got " + s);
                  }
                  o.objectRange[0] = v[0];
                  o.objectRange[1] = v[1];
                  o.hasObjectRange = true;
                } });
  t.push_back({ model,
                "--max-step",
                "MM",
                "upper bound on a vertex's displacement per iteration, physical units (mm); 0 means no bound",
                FormatNumber(GetCoreDefaults().MaximumStepLength),
                [&o](const std::string & s) {
                  o.maximumStepLength = ParseDouble("--max-step", s);
                  RequireAtLeast("--max-step", o.maximumStepLength, 0.0);
                } });
  t.push_back({ model,
                "--iterations",
                "N",
                "largest number of iterations of each resolution level; the first of several (the capture level) runs "
                "up to " +
                  std::to_string(defaults::CaptureIterations) + " when this is lower (0 writes the initial mesh)",
                std::to_string(defaults::Iterations),
                [&o](const std::string & s) { o.iterations = ParseUnsigned("--iterations", s); } });
  t.push_back({ model,
                "--tolerance",
                "MM",
                "stop when the largest vertex displacement stays below this length during --window iterations, "
                "physical units (mm); 0 always runs --iterations",
                FormatNumber(defaults::ConvergenceTolerance),
                [&o](const std::string & s) {
                  o.convergenceTolerance = ParseDouble("--tolerance", s);
                  RequireAtLeast("--tolerance", o.convergenceTolerance, 0.0);
                } });
  t.push_back({ model,
                "--window",
                "N",
                "consecutive quiet iterations that declare convergence, at least 1",
                std::to_string(GetCoreDefaults().ConvergenceWindow),
                [&o](const std::string & s) {
                  o.convergenceWindow = ParseUnsigned("--window", s);
                  RequireAtLeast("--window", o.convergenceWindow, 1);
                } });
  t.push_back({ model,
                "--active-fraction",
                "F",
                "a level is quiet when at most this fraction of its vertices move by --tolerance or more (0: when "
                "none does); a few vertices creeping into a narrow cleft then do not hold the whole surface, in [0, 1)",
                FormatNumber(defaults::ConvergenceFraction),
                [&o](const std::string & s) {
                  o.convergenceFraction = ParseDouble("--active-fraction", s);
                  RequireAtLeast("--active-fraction", o.convergenceFraction, 0.0);
                  if (!(o.convergenceFraction < 1.0))
                  {
                    throw Error("--active-fraction must be below 1; it is " + s);
                  }
                } });
  t.push_back({ model,
                "--no-damping",
                "",
                "do not damp the step of vertices whose displacement reverses their previous one (a vertex "
                "jumping back and forth across a thin gap or a sharp crest of the force never converges)",
                "damping on",
                [&o](const std::string &) { o.dampOscillations = false; } });
  AddGlobalOptions(t, global, "General");
  return t;
}

OptionTable
MakeDemoOptions(DemoOptions & o, GlobalOptions & global)
{
  OptionTable t;
  t.push_back({ "Options",
                "--output-dir",
                "DIR",
                "directory for the image, the force field, the meshes, the series and the figure (created if needed)",
                o.outputDirectory,
                [&o](const std::string & s) { o.outputDirectory = s; } });
  AddGlobalOptions(t, global, "Options");
  return t;
}

/** Greedy word wrap of \a text into lines of at most \a width characters. */
std::vector<std::string>
Wrap(const std::string & text, size_t width)
{
  std::vector<std::string> lines;
  std::istringstream       words(text);
  std::string              word;
  std::string              line;
  while (words >> word)
  {
    if (!line.empty() && line.size() + 1 + word.size() > width)
    {
      lines.push_back(line);
      line.clear();
    }
    line += (line.empty() ? "" : " ") + word;
  }
  if (!line.empty())
  {
    lines.push_back(line);
  }
  return lines;
}

void
PrintOptions(std::ostream & os, const OptionTable & table)
{
  constexpr size_t column = 30;
  constexpr size_t width = 100;
  std::string      section;
  for (const auto & option : table)
  {
    if (option.section != section)
    {
      section = option.section;
      os << "\n" << section << ":\n";
    }
    std::string head = "  " + option.name + (option.argument.empty() ? "" : " " + option.argument);
    std::string text = option.help;
    if (!option.defaultText.empty())
    {
      // Kept on one line: its spaces are protected from the word wrap.
      std::string unbreakable = "[default: " + option.defaultText + "]";
      std::replace(unbreakable.begin(), unbreakable.end(), ' ', '\x01');
      text += " " + unbreakable;
    }
    auto lines = Wrap(text, width - column);
    for (auto & line : lines)
    {
      std::replace(line.begin(), line.end(), '\x01', ' ');
    }
    if (head.size() + 2 > column)
    {
      os << head << "\n";
      head.clear();
    }
    for (size_t i = 0; i < lines.size(); ++i)
    {
      const std::string left = i == 0 ? head : std::string();
      os << left << std::string(column - left.size(), ' ') << lines[i] << "\n";
    }
  }
}

void
PrintMainHelp(std::ostream & os)
{
  os << "Usage: edmodel [--threads N] [--quiet] COMMAND [options]\n"
        "\n"
        "Explicit deformable model: a surface mesh moves, iteration after iteration, under a force field\n"
        "computed from a 3-D image and internal forces that keep it smooth, until it lies on the boundary\n"
        "of an object. Every length is in the image's physical units (mm).\n"
        "\n"
        "Commands:\n"
        "  segment    deform a sphere or a mesh onto the boundary of the object in an image\n"
        "  demo       the seed paper's example on a generated 64^3 ellipsoid image, with its accuracy\n"
        "\n"
        "Options:\n"
        "  --help, -h       this help (edmodel COMMAND --help for the options of a command)\n"
        "  --version        version of edmodel and of the libraries it uses\n"
        "  --threads N      number of threads used by the filters [default: all cores]\n"
        "  --quiet          no progress and no summary\n"
        "\n"
        "Examples:\n"
        "  edmodel demo --output-dir /tmp/edmodel-demo\n"
        "  edmodel segment --image liver.nii.gz --init-sphere 12.5,-40,80,15 --output liver.vtk\n"
        "  edmodel segment --image dicom/ --init-mesh start.obj --balloon 0.1 --output surface.off\n"
        "  edmodel segment --image slice.png --init-circle 60,40,8 --output contour.csv --overlay-png over.png\n"
        "\n"
        "Exit status: 0 success, 1 poor result or internal error, 2 bad command line or input.\n";
}

void
PrintSegmentHelp(std::ostream & os, const OptionTable & table)
{
  os << "Usage: edmodel segment --image IMG --output MESH [--init-sphere X,Y,Z,R | --init-mesh MESH] [options]\n"
        "       edmodel segment --image IMG2D --output CONTOUR [--init-circle X,Y,R | --init-contour FILE] [options]\n"
        "\n"
        "Computes the external force field of IMG, deforms the initial surface under it and writes the\n"
        "result. Lengths are in physical units (mm); coordinates in the image's physical frame (origin,\n"
        "spacing and direction honoured). The defaults need no tuning for images of any intensity range.\n"
        "\n"
        "2-D images (a 2-D file, or a volume of one slice): the model is a contour (a snake), started from\n"
        "--init-circle X,Y,R or --init-contour FILE instead of a sphere or a mesh, with the same filters,\n"
        "options and defaults (a circle of --circle-points points refined to --edge-length; the region\n"
        "force estimated inside the initial circle), except the elasticity, tangential on contours.\n"
        "A closed contour that grows around an obstacle and crosses itself loses its loops and is\n"
        "resampled (checked every 10 iterations; the written contour has no crossing edges).\n"
        "--output .vtk/.vtp/.csv writes the contour, --overlay-png draws it over the image. An open\n"
        "contour (--open, or an open polyline) has no region force or balloon; --fixed-boundary keeps\n"
        "its ends. --init-sphere and --init-mesh need a 3-D image, --init-circle and --init-contour a\n"
        "2-D one.\n"
        "  edmodel segment --image cells.png --init-circle 120,80,15 --output cell.csv --overlay-png cell.png\n";
  PrintOptions(os, table);
}

void
PrintDemoHelp(std::ostream & os, const OptionTable & table)
{
  os << "Usage: edmodel demo [--output-dir DIR]\n"
        "\n"
        "The seed paper's example end to end: a 64^3 binary image of an ellipsoid of radii (18, 14, 28)\n"
        "voxels centred at (31, 31, 31), a sphere of radius 16 at the centre deformed onto it with the\n"
        "default segment parameters plus gradient vector flow (--gvf). Writes the image (demo-image.nii.gz),\n"
        "the force field (demo-force.mha), the initial and final meshes (demo-sphere.vtk, demo-mesh.vtk)\n"
        "and, when built with VTK, the time series (series/demo.pvd, every 10 iterations) and the seed's\n"
        "Figure 1 (demo-figure1.png: the mesh over the middle slice of the image at iterations 0, 10, 50\n"
        "and the last; Debian's VTK renders through X, so without a display the figure is skipped with a\n"
        "message: run under xvfb-run -a). Prints the mean and largest distance of the final mesh to the\n"
        "true ellipsoid, and exits with 1 when that accuracy is poor.\n";
  PrintOptions(os, table);
}

/** Applies the options of \a table found in args[first...]; returns false when
 * --help was asked. */
bool
ParseOptions(const std::vector<std::string> & args,
             size_t                           first,
             const OptionTable &              table,
             const std::string &              command)
{
  for (size_t i = first; i < args.size(); ++i)
  {
    std::string arg = args[i];
    if (arg == "--help" || arg == "-h")
    {
      return false;
    }
    std::string value;
    bool        hasValue = false;
    const auto  equal = arg.find('=');
    if (arg.compare(0, 2, "--") == 0 && equal != std::string::npos)
    {
      value = arg.substr(equal + 1);
      arg = arg.substr(0, equal);
      hasValue = true;
    }
    const Option * option = nullptr;
    for (const auto & candidate : table)
    {
      if (candidate.name == arg)
      {
        option = &candidate;
      }
    }
    if (option == nullptr)
    {
      throw Error("unknown option '" + args[i] + "' (see 'edmodel " + command + " --help')");
    }
    if (option->argument.empty())
    {
      if (hasValue)
      {
        throw Error(arg + " takes no value");
      }
    }
    else if (!hasValue)
    {
      if (i + 1 >= args.size())
      {
        throw Error(arg + " needs a value (" + option->argument + ")");
      }
      value = args[++i];
    }
    option->apply(value);
  }
  return true;
}

int
Main(const std::vector<std::string> & args)
{
  GlobalOptions global;
  OptionTable   globalTable;
  AddGlobalOptions(globalTable, global, "Options");

  size_t i = 1;
  for (; i < args.size(); ++i)
  {
    const std::string & arg = args[i];
    if (arg == "--help" || arg == "-h")
    {
      PrintMainHelp(std::cout);
      return ExitSuccess;
    }
    if (arg == "--version")
    {
      std::cout << "edmodel " << EDM_VERSION << " (ExplicitDeformableModel; " << GetLibraryVersions() << ")\n";
      return ExitSuccess;
    }
    if (arg.compare(0, 1, "-") != 0)
    {
      break;
    }
    // A global option before the command.
    const auto equal = arg.find('=');
    const auto name = arg.substr(0, equal);
    if (name == "--threads" || name == "--quiet")
    {
      std::vector<std::string> one{ args[0], arg };
      if (name == "--threads" && equal == std::string::npos)
      {
        if (i + 1 >= args.size())
        {
          throw Error("--threads needs a value (N)");
        }
        one.push_back(args[++i]);
      }
      ParseOptions(one, 1, globalTable, "");
      continue;
    }
    throw Error("unknown option '" + arg + "' (see 'edmodel --help')");
  }
  if (i >= args.size())
  {
    throw Error("no command given: use 'edmodel segment' or 'edmodel demo' (see 'edmodel --help')");
  }

  const std::string command = args[i];
  if (command == "help")
  {
    PrintMainHelp(std::cout);
    return ExitSuccess;
  }
  if (command == "segment")
  {
    SegmentOptions    options;
    const OptionTable table = MakeSegmentOptions(options, global);
    if (!ParseOptions(args, i + 1, table, command))
    {
      PrintSegmentHelp(std::cout, table);
      return ExitSuccess;
    }
    if (options.image.empty())
    {
      throw Error("segment: --image is required (see 'edmodel segment --help')");
    }
    if (options.output.empty())
    {
      throw Error("segment: --output is required (see 'edmodel segment --help')");
    }
    if (options.hasInitSphere && !options.initMesh.empty())
    {
      throw Error("segment: give --init-sphere or --init-mesh, not both");
    }
    if (options.snapshotEverySet && options.snapshots.empty())
    {
      throw Error("segment: --every needs --snapshots DIR");
    }
    const bool contour = options.hasInitCircle || !options.initContour.empty();
    if (options.hasInitCircle && !options.initContour.empty())
    {
      throw Error("segment: give --init-circle or --init-contour, not both");
    }
    if (contour && (options.hasInitSphere || !options.initMesh.empty()))
    {
      throw Error(std::string("segment: give a 2-D initial contour (--init-circle, --init-contour) or a 3-D initial ") +
                  "surface (--init-sphere, --init-mesh), not both");
    }
    if (options.openContour && options.initContour.empty())
    {
      throw Error("segment: --open applies to the contours of --init-contour FILE.csv");
    }
    // An output that is an input would replace it.
    const std::vector<std::string> inputs{ options.image, options.initMesh, options.initContour };
    CheckNotAnInput(options.output, "--output", inputs);
    if (!options.forceOutput.empty())
    {
      CheckNotAnInput(options.forceOutput, "--force-output", inputs);
      std::error_code error;
      if (std::filesystem::weakly_canonical(options.forceOutput, error) ==
          std::filesystem::weakly_canonical(options.output, error))
      {
        throw Error("--force-output: '" + options.forceOutput + "' is also the --output mesh");
      }
    }
    if (!options.overlayPng.empty())
    {
      CheckNotAnInput(options.overlayPng, "--overlay-png", inputs);
    }
    // The image's dimension chooses the model: a contour in 2-D, a surface in
    // 3-D. An image whose header cannot be read goes the 3-D way, which
    // reports it after checking the outputs, as it always has.
    unsigned int dimension = 3;
    std::string  description;
    try
    {
      const ImageInfo info = ReadImageInfo(options.image);
      dimension = info.dimension;
      description = info.description;
    }
    catch (const Error &)
    {
      dimension = contour ? 2 : 3;
    }
    const std::string image = "'" + options.image + "'";
    if (dimension == 2 && (options.hasInitSphere || !options.initMesh.empty()))
    {
      throw Error(std::string(options.hasInitSphere ? "--init-sphere" : "--init-mesh") + " needs a 3-D image: " +
                  image + " is 2-D (" + description + "); use --init-circle X,Y,R or --init-contour FILE");
    }
    if (dimension != 2 && contour)
    {
      throw Error(std::string(options.hasInitCircle ? "--init-circle" : "--init-contour") +
                  " needs a 2-D image: " + image + " is " + std::to_string(dimension) + "-D" +
                  (description.empty() ? std::string() : " (" + description + ")") +
                  "; use --init-sphere X,Y,Z,R or --init-mesh FILE");
    }
    if (dimension != 2 && !options.overlayPng.empty())
    {
      throw Error("--overlay-png draws a contour over a 2-D image: " + image + " is " + std::to_string(dimension) +
                  "-D" + (description.empty() ? std::string() : " (" + description + ")"));
    }
    SetNumberOfThreads(global.threads);
    if (dimension == 2)
    {
      return RunSegmentContour(options, global);
    }
    return RunSegment(options, global);
  }
  if (command == "demo")
  {
    DemoOptions       options;
    const OptionTable table = MakeDemoOptions(options, global);
    if (!ParseOptions(args, i + 1, table, command))
    {
      PrintDemoHelp(std::cout, table);
      return ExitSuccess;
    }
    SetNumberOfThreads(global.threads);
    return RunDemo(options, global);
  }
  throw Error("unknown command '" + command + "' (see 'edmodel --help')");
}

} // namespace
} // namespace edm

int
main(int argc, char * argv[])
{
  // First, before any thread starts: signals remove the temporary outputs.
  edm::InstallSignalCleanup();
  const std::vector<std::string> args(argv, argv + argc);
  try
  {
    return edm::Main(args);
  }
  catch (const edm::Error & error)
  {
    std::cerr << "edmodel: " << error.what() << std::endl;
    return error.GetExitCode();
  }
  catch (const std::bad_alloc &)
  {
    std::cerr << "edmodel: out of memory (the input is too large for this machine or its memory limit)" << std::endl;
    return edm::ExitUsage;
  }
  catch (const std::exception & error)
  {
    std::string message = error.what();
    for (auto & c : message)
    {
      c = (c == '\n' || c == '\r') ? ' ' : c;
    }
    std::cerr << "edmodel: internal error: " << message << std::endl;
    return edm::ExitFailure;
  }
}
