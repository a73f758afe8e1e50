#!/usr/bin/env python3
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
"""2-D contours through `import edmodel`: a circle pulled onto an ellipse
over a 2-D vtkImageData (72 x 72 x 1 points, in the plane z = 2), through
edmodel.vtkExternalForceField and edmodel.vtkDeformableMesh.

Known answer: the ellipse of semi-axes (20, 14) pixels centred at (35.3,
36.1), imaged anti-aliased; a closed polyline of 200 points on the circle of
radius 17 at its centre must end within 0.1 pixel of it on average, 0.3 at
most, in the image's plane, run one update per iteration. Also: the scenario
of the ParaView 2-D test (ScaleFactor 0.1, 32 steps: the mean distance falls
at every step), an open contour whose ends FixedBoundary keeps exactly, a
refused input (the balloon on an open contour), and a time series. Exits
non-zero on failure.
"""

import math
import os
import sys
import tempfile

import edmodel
from vtkmodules.vtkCommonCore import vtkCommand, vtkFloatArray, vtkPoints
from vtkmodules.vtkCommonDataModel import vtkCellArray, vtkImageData, vtkPolyData

SIZE = 72
PLANE_Z = 2.0
CENTER = (35.3, 36.1)
RADII = (20.0, 14.0)


def check(condition, message):
    if not condition:
        print("FAILED:", message, flush=True)
        sys.exit(1)
    print("ok:", message, flush=True)


def distance_to_ellipse(p):
    """Euclidean distance from p to the ellipse, by bisection on the Lagrange
    multiplier t of the closest point problem."""
    z = [abs(p[k] - CENTER[k]) for k in range(2)]
    a2 = [r * r for r in RADII]

    def g(t):
        return sum((RADII[k] * z[k] / (t + a2[k])) ** 2 for k in range(2)) - 1.0

    low = -min(a2)
    high = max(RADII) * math.hypot(*z) + 1.0
    for _ in range(200):
        middle = 0.5 * (low + high)
        if g(middle) > 0.0:
            low = middle
        else:
            high = middle
    t = 0.5 * (low + high)
    closest = [min(a2[k] * z[k] / (t + a2[k]), RADII[k]) for k in range(2)]
    return math.hypot(z[0] - closest[0], z[1] - closest[1])


def distances(polydata):
    d = [distance_to_ellipse(polydata.GetPoint(i)) for i in range(polydata.GetNumberOfPoints())]
    return sum(d) / len(d), max(d)


def points(polydata):
    return [polydata.GetPoint(i) for i in range(polydata.GetNumberOfPoints())]


def make_image():
    """The anti-aliased ellipse: 100 x the fraction of each pixel's 16 x 16
    sub-samples inside it."""
    image = vtkImageData()
    image.SetDimensions(SIZE, SIZE, 1)
    image.SetOrigin(0.0, 0.0, PLANE_Z)
    values = vtkFloatArray()
    values.SetName("Intensity")
    values.SetNumberOfTuples(SIZE * SIZE)
    sub = [(-0.5 + (a + 0.5) / 16.0) for a in range(16)]
    for j in range(SIZE):
        for i in range(SIZE):
            count = 0
            for du in sub:
                u = (i + du - CENTER[0]) / RADII[0]
                u2 = u * u
                if u2 > 1.0:
                    continue
                for dv in sub:
                    v = (j + dv - CENTER[1]) / RADII[1]
                    count += u2 + v * v <= 1.0
            values.SetValue(i + SIZE * j, 100.0 * count / 256.0)
    image.GetPointData().SetScalars(values)
    return image


def make_polyline(xy, closed):
    polydata = vtkPolyData()
    pts = vtkPoints()
    pts.SetDataTypeToDouble()
    for x, y in xy:
        pts.InsertNextPoint(x, y, PLANE_Z)
    lines = vtkCellArray()
    n = len(xy)
    lines.InsertNextCell(n + 1 if closed else n)
    for k in range(n):
        lines.InsertCellPoint(k)
    if closed:
        lines.InsertCellPoint(0)
    polydata.SetPoints(pts)
    polydata.SetLines(lines)
    return polydata


def make_circle(radius, n):
    return make_polyline([(CENTER[0] + radius * math.cos(2.0 * math.pi * k / n),
                           CENTER[1] + radius * math.sin(2.0 * math.pi * k / n)) for k in range(n)], True)


def make_open_contour(n):
    """From (c - 12, c - 9) to (c + 12, c - 9), bowed 3 pixels down at the
    middle: 2 pixels inside the bottom of the ellipse (at c - 14)."""
    xy = []
    for k in range(n):
        s = k / (n - 1)
        xy.append((CENTER[0] - 12.0 + 24.0 * s, CENTER[1] - 9.0 - 12.0 * s * (1.0 - s)))
    return make_polyline(xy, False)


image = make_image()
forces = edmodel.vtkExternalForceField()
forces.SetInputData(image)
forces.SetSigma(1.0)
forces.Update()
field = forces.GetOutput()
check(field.GetDimensions() == (SIZE, SIZE, 1) and field.GetOrigin()[2] == PLANE_Z,
      "Force Field keeps the 2-D image's geometry and plane")
force = field.GetPointData().GetArray("Force")
check(force is not None and force.GetNumberOfComponents() == 3 and force.GetRange(2) == (0.0, 0.0),
      "the 2-D force is a 3-component array whose third component is 0")

# One update of 400 iterations, then the same step by step.
circle = make_circle(17.0, 200)
before = distances(circle)
deformable = edmodel.vtkDeformableMesh()
deformable.SetInputData(circle)
deformable.SetForceImageConnection(forces.GetOutputPort())
deformable.SetScaleFactor(0.5)
deformable.SetElasticity(0.3)
deformable.SetNumberOfIterations(400)
deformable.Update()
output = deformable.GetOutput()
after = distances(output)
print("circle -> ellipse: mean %.4f pixel before, mean %.4f max %.4f after" % (before[0], after[0], after[1]))
check(deformable.GetMeshDimension() == 2 and deformable.GetNumberOfClosedContours() == 1,
      "a 2-D model of one closed contour")
check(output.GetNumberOfPoints() == 200 and output.GetNumberOfLines() == 1, "the output has the input's polyline")
check(before[0] > 1.0, "the circle starts off the ellipse (%.3f)" % before[0])
check(after[0] <= 0.1 and after[1] <= 0.3, "the contour ends on the ellipse: mean %.4f <= 0.1, max %.4f <= 0.3 pixel"
      % after)
check(all(p[2] == PLANE_Z for p in points(output)), "the contour lies in the image's plane z = %g" % PLANE_Z)

stepwise = edmodel.vtkDeformableMesh()
stepwise.SetInputData(circle)
stepwise.SetForceImageConnection(forces.GetOutputPort())
stepwise.SetScaleFactor(0.5)
stepwise.SetElasticity(0.3)
stepwise.IterateFromZeroOff()
progress = []
stepwise.AddObserver(vtkCommand.ProgressEvent, lambda caller, event: progress.append(caller.GetProgress()))
one_step_each = True
for n in range(0, 401):
    progress.clear()
    stepwise.SetNumberOfIterations(n)
    stepwise.Update()
    # 0 and 1 from the executive, k / K from the ITK filter after each of its K steps.
    steps = sum(1 for p in progress if p > 0.0) - 1
    one_step_each = one_step_each and stepwise.GetCurrentIteration() == n and steps == (1 if n > 0 else 0)
check(one_step_each, "step by step: each update ran exactly one more iteration (progress count)")
check(points(stepwise.GetOutput()) == points(output), "400 single steps give the contour of one update of 400")

# The ParaView 2-D test's scenario: ScaleFactor 0.1, 32 steps, the mean
# distance to the ellipse falls at every step.
animated = edmodel.vtkDeformableMesh()
animated.SetInputData(circle)
animated.SetForceImageConnection(forces.GetOutputPort())
animated.SetScaleFactor(0.1)
animated.IterateFromZeroOff()
means = [before[0]]
for n in range(1, 33):
    animated.SetNumberOfIterations(n)
    animated.Update()
    means.append(distances(animated.GetOutput())[0])
print("ScaleFactor 0.1, 32 steps: mean distance %s" % " ".join("%.3f" % m for m in means[::4] + [means[-1]]))
check(all(b < a for a, b in zip(means, means[1:])), "the mean distance falls at every step (%.3f -> %.3f)"
      % (means[0], means[-1]))

# An open contour: FixedBoundary keeps its ends, its middle reaches the edge.
open_contour = make_open_contour(41)
pinned = edmodel.vtkDeformableMesh()
pinned.SetInputData(open_contour)
pinned.SetForceImageConnection(forces.GetOutputPort())
pinned.SetScaleFactor(0.5)
pinned.SetElasticity(0.3)
pinned.FixedBoundaryOn()
pinned.SetNumberOfIterations(300)
pinned.Update()
out = pinned.GetOutput()
check(pinned.GetNumberOfOpenContours() == 1, "one open contour")
check(out.GetPoint(0) == open_contour.GetPoint(0) and out.GetPoint(40) == open_contour.GetPoint(40),
      "FixedBoundary keeps the ends exactly: %s, %s" % (out.GetPoint(0), out.GetPoint(40)))
check(distance_to_ellipse(out.GetPoint(20)) <= 0.3, "the middle reaches the edge (%.4f pixel)"
      % distance_to_ellipse(out.GetPoint(20)))

# The balloon on an open contour: outward is undefined.
errors = []
pinned.AddObserver(vtkCommand.ErrorEvent, lambda caller, event, data=None: errors.append(event))
pinned.SetBalloon(0.1)
pinned.Update()
check(len(errors) >= 1 and pinned.GetOutput().GetNumberOfPoints() == 0,
      "the balloon on an open contour: an error and an empty output")

# The time series of the contour.
with tempfile.TemporaryDirectory() as directory:
    writer = edmodel.vtkIterationSeriesWriter()
    writer.SetAlgorithm(deformable)
    writer.SetFileName(os.path.join(directory, "contour.pvd"))
    writer.SetInterval(10)
    writer.SetNumberOfIterations(25)
    check(writer.Write() == 1, "the contour's series is written")
    written = [writer.GetWrittenIteration(k) for k in range(writer.GetNumberOfWrittenFiles())]
    check(written == [0, 10, 20, 25], "iterations 0, 10, 20 and 25 written (%s)" % written)
    check(all(os.path.getsize(writer.GetWrittenFileName(k)) > 0 for k in range(4)), "the .vtp files exist")

print("edmodel contour test passed")
