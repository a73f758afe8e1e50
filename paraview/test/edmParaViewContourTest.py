#!/usr/bin/env pvpython
#
#  Copyright NumFOCUS
#
#  Licensed under the Apache License, Version 2.0 (the "License");
#  you may not use this file except in compliance with the License.
#  You may obtain a copy of the License at
#
#         http://www.apache.org/licenses/LICENSE-2.0.txt
#
#  Unless required by applicable law or agreed to in writing, software
#  distributed under the License is distributed on an "AS IS" BASIS,
#  WITHOUT WARRANTIES OR CONDITIONS OF ANY KIND, either express or implied.
#  See the License for the specific language governing permissions and
#  limitations under the License.
"""The ParaView plugin on a 2-D image and contours (pvpython, builtin session).

A 72 x 72 x 1 image in the plane z = 2 holds an anti-aliased ellipse of
semi-axes (20, 14) pixels centred at (35.3, 36.1); Force Field computes its
2-D force field; Deformable Mesh deforms a closed polyline of 200 points on
the circle of radius 17 at the ellipse's centre (given at z = 0). An
animation scene whose track drives NumberOfIterations, IterateFromZero off,
is stepped 32 times (ScaleFactor 0.1). At every time step:

- NumberOfIterations and CurrentIteration follow the frame number, and the
  filter ran one ITK step (progress count);
- the model is 2-D (MeshDimension), the contour lies in the image's plane and
  is closer to the analytic ellipse than at the previous step.

The animated contour must equal the one computed from zero. Then the known
answer (ScaleFactor 0.5, Elasticity 0.3, 400 iterations: within 0.1 pixel on
average, 0.3 at most, of the ellipse) and an open contour whose ends
FixedBoundary keeps exactly. A screenshot of the contours over the force
field is saved and must not be blank. Exits non-zero on failure, 77 when
there is no display.

The numbers of the animation are those of vtk/test/edmodelContourTest.py,
which runs the same case through plain VTK.
"""

import argparse
import builtins
import math
import os
import sys

import numpy as np

# The 3-D test's helpers: check, the probe of a filter's updates, the
# screenshot check.
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from edmParaViewPluginTest import UpdateProbe, check, check_not_blank, points_of  # noqa: E402

SIZE = 72
PLANE_Z = 2.0
CENTER = np.array([35.3, 36.1])
RADII = np.array([20.0, 14.0])


def distances_to_ellipse(points):
    """Euclidean distances from points (n x 3, z ignored) to the ellipse:
    bisection on the Lagrange multiplier t of the closest-point problem,
    sum_k (r_k z_k / (t + r_k^2))^2 = 1, vectorised over the points."""
    z = np.abs(points[:, :2] - CENTER)
    r2 = RADII ** 2
    low = np.full(len(z), -r2.min())
    high = np.full(len(z), RADII.max() * np.linalg.norm(z, axis=1) + 1.0)

    def g(t):
        return (((RADII * z) / (t[:, None] + r2)) ** 2).sum(axis=1) - 1.0

    for _ in range(200):
        middle = 0.5 * (low + high)
        above = g(middle) > 0.0
        low = np.where(above, middle, low)
        high = np.where(above, high, middle)
    t = 0.5 * (low + high)
    closest = np.minimum(r2 * z / (t[:, None] + r2), RADII)
    return np.linalg.norm(z - closest, axis=1)


def parse_arguments():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--plugin", required=True, help="the plugin's shared library")
    parser.add_argument("--screenshot", required=True, help="PNG to write")
    parser.add_argument("--steps", type=int, default=32,
                        help="animation time steps (a power of 2 keeps the key frame interpolation exact)")
    return parser.parse_args()


def make_ellipse_image(simple):
    """The 2-D image: 100 x the fraction of each pixel's 16 x 16 sub-samples
    inside the ellipse, point array Intensity, in the plane z = PLANE_Z."""
    image = simple.ProgrammableSource(OutputDataSetType="vtkImageData")
    image.ScriptRequestInformation = (
        "from vtkmodules.vtkCommonDataModel import vtkDataObject\n"
        "executive = self.GetExecutive()\n"
        "info = executive.GetOutputInformation(0)\n"
        "info.Set(executive.WHOLE_EXTENT(), 0, %d, 0, %d, 0, 0)\n"
        "info.Set(vtkDataObject.ORIGIN(), 0.0, 0.0, %r)\n"
        "info.Set(vtkDataObject.SPACING(), 1.0, 1.0, 1.0)\n" % (SIZE - 1, SIZE - 1, PLANE_Z))
    image.Script = (
        "import numpy as np\n"
        "from vtkmodules.util.numpy_support import numpy_to_vtk\n"
        "n = %d\n"
        "output = self.GetOutput()\n"
        "output.SetExtent(0, n - 1, 0, n - 1, 0, 0)\n"
        "output.SetOrigin(0.0, 0.0, %r)\n"
        "output.SetSpacing(1.0, 1.0, 1.0)\n"
        "s = (np.arange(16) + 0.5) / 16.0 - 0.5\n"
        "j, i = np.mgrid[0:n, 0:n]\n"
        "x = i[:, :, None, None] + s[None, None, :, None]\n"
        "y = j[:, :, None, None] + s[None, None, None, :]\n"
        "inside = ((x - %r) / %r) ** 2 + ((y - %r) / %r) ** 2 <= 1.0\n"
        "values = 100.0 * inside.mean(axis=(2, 3))\n"
        "array = numpy_to_vtk(values.astype(np.float32).ravel(), deep=1)\n"
        "array.SetName('Intensity')\n"
        "output.GetPointData().SetScalars(array)\n"
        % (SIZE, PLANE_Z, CENTER[0], RADII[0], CENTER[1], RADII[1]))
    image.UpdatePipeline()
    return image


def make_polyline(simple, xy, closed):
    """A programmable source of one polyline through the points xy (z = 0),
    closed by its first point when asked."""
    source = simple.ProgrammableSource(OutputDataSetType="vtkPolyData")
    source.Script = (
        "from vtkmodules.vtkCommonCore import vtkPoints\n"
        "from vtkmodules.vtkCommonDataModel import vtkCellArray\n"
        "xy = %r\n"
        "closed = %r\n"
        "points = vtkPoints()\n"
        "points.SetDataTypeToDouble()\n"
        "lines = vtkCellArray()\n"
        "lines.InsertNextCell(len(xy) + 1 if closed else len(xy))\n"
        "for k, (x, y) in enumerate(xy):\n"
        "    points.InsertNextPoint(x, y, 0.0)\n"
        "    lines.InsertCellPoint(k)\n"
        "if closed:\n"
        "    lines.InsertCellPoint(0)\n"
        "output = self.GetOutput()\n"
        "output.SetPoints(points)\n"
        "output.SetLines(lines)\n" % ([(float(x), float(y)) for x, y in xy], closed))
    source.UpdatePipeline()
    return source


def main():
    arguments = parse_arguments()
    if not os.environ.get("DISPLAY"):
        print("No display: run under xvfb-run. Skipped.")
        return 77

    import paraview.simple as simple

    simple.LoadPlugin(arguments.plugin, remote=False)
    for function in ("DeformableMesh", "ForceField"):
        check(hasattr(simple, function), "the plugin adds the filter function " + function)
    DeformableMesh = simple.DeformableMesh
    ForceField = simple.ForceField

    image = make_ellipse_image(simple)
    forces = ForceField(Input=image)
    forces.IntensityArray = ["POINTS", "Intensity"]
    forces.Sigma = 1.0
    forces.UpdatePipeline()
    force_data = forces.GetClientSideObject().GetOutputDataObject(0)
    plane_z = force_data.GetOrigin()[2]
    check(force_data.GetDimensions() == (SIZE, SIZE, 1) and forces.PointData["Force"].GetNumberOfComponents() == 3,
          "Force Field on a 2-D image: a 3-component point array Force on its %d x %d x 1 points" % (SIZE, SIZE))
    check(forces.PointData["Force"].GetRange(2) == (0.0, 0.0), "the third component of the 2-D force is 0")
    print("the image's plane: z = %g" % plane_z)

    n_points = 200
    # As edmodelContourTest.py makes it (math, not numpy: the same bits).
    circle_xy = [(float(CENTER[0]) + 17.0 * math.cos(2.0 * math.pi * k / n_points),
                  float(CENTER[1]) + 17.0 * math.sin(2.0 * math.pi * k / n_points)) for k in range(n_points)]
    circle = make_polyline(simple, circle_xy, closed=True)
    mesh = DeformableMesh(Input=circle, Vectors=forces)
    check(list(mesh.ForceArray) == ["POINTS", "Force"], "Deformable Mesh takes Force from its Vectors input")
    check(mesh.GetProperty("FixedBoundary") is not None and mesh.FixedBoundary == 0,
          "the panel has FixedBoundary, unchecked by default")
    mesh.ScaleFactor = 0.1
    mesh.IterateFromZero = 0
    mesh.NumberOfIterations = 0

    view = simple.CreateView("RenderView")
    view.ViewSize = [800, 600]
    view.OrientationAxesVisibility = 0
    image_display = simple.Show(forces, view)
    image_display.SetRepresentationType("Slice")
    simple.ColorBy(image_display, ("POINTS", "Force", "Magnitude"))
    force_colours = simple.GetColorTransferFunction("Force")
    force_colours.ApplyPreset("Inferno (matplotlib)", True)
    force_colours.RescaleTransferFunction(0.0, 1.0)
    mesh_display = simple.Show(mesh, view)
    mesh_display.ColorArrayName = ["POINTS", ""]
    mesh_display.AmbientColor = [0.55, 0.85, 1.0]
    mesh_display.DiffuseColor = [0.55, 0.85, 1.0]
    mesh_display.LineWidth = 3.0
    view.Background = [0.32, 0.34, 0.43]
    simple.Render(view)  # the first render resets the camera: place it after
    view.CameraPosition = [CENTER[0], CENTER[1], plane_z + 150.0]
    view.CameraFocalPoint = [CENTER[0], CENTER[1], plane_z]
    view.CameraViewUp = [0.0, 1.0, 0.0]
    simple.Render(view)

    # The animation: a track on NumberOfIterations from 0 to N over N + 1 frames.
    n = arguments.steps
    scene = simple.GetAnimationScene()
    scene.PlayMode = "Sequence"
    scene.StartTime = 0.0
    scene.EndTime = 1.0
    scene.NumberOfFrames = n + 1
    track = simple.GetAnimationTrack("NumberOfIterations", index=0, proxy=mesh)
    track.KeyFrames = [simple.CompositeKeyFrame(KeyTime=0.0, KeyValues=[0]),
                       simple.CompositeKeyFrame(KeyTime=1.0, KeyValues=[n])]
    scene.GoToFirst()

    algorithm = mesh.GetClientSideObject()
    probe = UpdateProbe(algorithm)
    initial = points_of(circle.GetClientSideObject().GetOutputDataObject(0))
    distances = [distances_to_ellipse(initial).mean()]
    print("step 0: mean distance to the ellipse %.4f pixel" % distances[0])
    for frame in range(1, n + 1):
        probe.reset()
        scene.GoToNext()
        mesh.UpdatePropertyInformation()
        current = mesh.GetPropertyValue("CurrentIteration")
        dimension = mesh.GetPropertyValue("MeshDimension")
        requested = mesh.NumberOfIterations
        output = algorithm.GetOutputDataObject(0)
        contour = points_of(output)
        distances.append(distances_to_ellipse(contour).mean())
        steps = probe.steps()
        print("step %d: NumberOfIterations %d, CurrentIteration %d, MeshDimension %d, %d ITK step(s),"
              " mean distance %.4f" % (frame, requested, current, dimension, steps, distances[-1]), flush=True)
        if requested != frame or current != frame:
            check(False, "NumberOfIterations and CurrentIteration follow the animation at step %d" % frame)
        if steps != 1:
            check(False, "one ITK step per animation step (step %d ran %d)" % (frame, steps))
        if dimension != 2 or output.GetNumberOfLines() != 1 or not np.all(contour[:, 2] == plane_z):
            check(False, "a 2-D model whose contour lies in the image's plane at step %d" % frame)
        if not distances[-1] < distances[-2]:
            check(False, "the contour approaches the ellipse at step %d (%.4f after %.4f)"
                  % (frame, distances[-1], distances[-2]))
    check(True, "over %d animation steps: CurrentIteration followed the frame, one ITK step each, the contour"
                " in the plane z = %g" % (n, plane_z))
    check(builtins.all(b < a for a, b in zip(distances, distances[1:])),
          "the mean distance to the ellipse decreased at every step: %.4f -> %.4f" % (distances[0], distances[-1]))
    animated = points_of(algorithm.GetOutputDataObject(0)).copy()

    simple.SaveScreenshot(arguments.screenshot, view, ImageResolution=[800, 600])
    check_not_blank(arguments.screenshot)

    # From zero: the same contour.
    mesh.IterateFromZero = 1
    mesh.NumberOfIterations = n
    mesh.UpdatePipeline()
    check(np.array_equal(points_of(algorithm.GetOutputDataObject(0)), animated),
          "the animated contour equals the contour computed from zero")

    # The known answer.
    mesh.ScaleFactor = 0.5
    mesh.Elasticity = 0.3
    mesh.NumberOfIterations = 400
    mesh.UpdatePipeline()
    mesh.UpdatePropertyInformation()
    final = distances_to_ellipse(points_of(algorithm.GetOutputDataObject(0)))
    print("400 iterations: mean %.4f, max %.4f pixel from the ellipse; %d closed contour(s)"
          % (final.mean(), final.max(), mesh.GetPropertyValue("NumberOfClosedContours")))
    check(mesh.GetPropertyValue("NumberOfClosedContours") == 1, "one closed contour")
    check(final.mean() <= 0.1 and final.max() <= 0.3, "the contour ends on the ellipse (mean <= 0.1, max <= 0.3)")

    # An open contour bowed down to 2 pixels inside the bottom of the ellipse, its ends pinned.
    open_xy = [(float(CENTER[0]) - 12.0 + 24.0 * s, float(CENTER[1]) - 9.0 - 12.0 * s * (1.0 - s))
               for s in (k / 40.0 for k in range(41))]
    open_source = make_polyline(simple, open_xy, closed=False)
    pinned = DeformableMesh(Input=open_source, Vectors=forces)
    pinned.ScaleFactor = 0.5
    pinned.Elasticity = 0.3
    pinned.FixedBoundary = 1
    pinned.NumberOfIterations = 300
    pinned.UpdatePipeline()
    pinned.UpdatePropertyInformation()
    result = points_of(pinned.GetClientSideObject().GetOutputDataObject(0))
    check(pinned.GetPropertyValue("NumberOfOpenContours") == 1, "one open contour")
    check(np.array_equal(result[[0, 40], :2], np.array([open_xy[0], open_xy[40]])),
          "FixedBoundary keeps the ends exactly: %s, %s" % (result[0], result[40]))
    middle = distances_to_ellipse(result[20:21])[0]
    check(middle <= 0.3, "the middle of the open contour reaches the edge (%.4f pixel)" % middle)

    # Destroy the pipeline and the view while the display is open.
    simple.Disconnect()
    return 0


if __name__ == "__main__":
    sys.exit(main())
