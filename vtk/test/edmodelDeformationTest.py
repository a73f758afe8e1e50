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
"""End-to-end deformation through `import edmodel`, as in the seed paper's
DeformableMesh example: a sphere pulled onto an ellipsoid by the gradient of
the gradient magnitude of its image, computed with VTK's own image filters.

Known answer: the ellipsoid of radii (12, 10, 12) centred at (23.5, 23.5,
23.5) in a 48^3 image of unit voxels. The sphere of radius 11 starts about
0.64 voxel from the surface on average and must end within 0.25 voxel.
Step by step updates must reach the same mesh as one update, and the time
series writer must write a collection. Exits non-zero on failure.
"""

import math
import os
import sys
import tempfile

import edmodel
from vtkmodules.vtkCommonCore import vtkCommand
from vtkmodules.vtkFiltersSources import vtkSphereSource
from vtkmodules.vtkImagingCore import vtkImageCast
from vtkmodules.vtkImagingGeneral import (vtkImageGaussianSmooth, vtkImageGradient,
                                          vtkImageGradientMagnitude)
from vtkmodules.vtkImagingSources import vtkImageEllipsoidSource

CENTER = (23.5, 23.5, 23.5)
RADII = (12.0, 10.0, 12.0)


def distance_to_ellipsoid(p):
    """Euclidean distance from p to the ellipsoid's surface, by bisection on
    the Lagrange multiplier t of the closest point problem."""
    z = [abs(p[k] - CENTER[k]) for k in range(3)]
    a2 = [r * r for r in RADII]

    def g(t):
        return sum((RADII[k] * z[k] / (t + a2[k])) ** 2 for k in range(3)) - 1.0

    low = -min(a2)
    high = max(RADII) * math.sqrt(sum(v * v for v in z)) + 1.0
    for _ in range(200):
        middle = 0.5 * (low + high)
        if middle <= -min(a2) or g(middle) > 0.0:
            low = middle
        else:
            high = middle
    t = 0.5 * (low + high)
    closest = [min(a2[k] * z[k] / (t + a2[k]), RADII[k]) if t + a2[k] > 0 else RADII[k] for k in range(3)]
    return math.sqrt(sum((z[k] - closest[k]) ** 2 for k in range(3)))


def mean_distance(polydata):
    n = polydata.GetNumberOfPoints()
    return sum(distance_to_ellipsoid(polydata.GetPoint(i)) for i in range(n)) / n


def points(polydata):
    return [polydata.GetPoint(i) for i in range(polydata.GetNumberOfPoints())]


def check(condition, message):
    if not condition:
        print("FAILED:", message)
        sys.exit(1)
    print("ok:", message)


# The image and its force field: grad |grad (G * I)|, VTK's filters.
ellipsoid = vtkImageEllipsoidSource()
ellipsoid.SetWholeExtent(0, 47, 0, 47, 0, 47)
ellipsoid.SetCenter(*CENTER)
ellipsoid.SetRadius(*RADII)
ellipsoid.SetInValue(255.0)
ellipsoid.SetOutValue(0.0)
ellipsoid.SetOutputScalarTypeToFloat()
smooth = vtkImageGaussianSmooth()
smooth.SetInputConnection(ellipsoid.GetOutputPort())
smooth.SetDimensionality(3)
smooth.SetStandardDeviations(1.0, 1.0, 1.0)
smooth.SetRadiusFactors(3.0, 3.0, 3.0)
magnitude = vtkImageGradientMagnitude()
magnitude.SetInputConnection(smooth.GetOutputPort())
magnitude.SetDimensionality(3)
cast = vtkImageCast()
cast.SetInputConnection(magnitude.GetOutputPort())
cast.SetOutputScalarTypeToFloat()
gradient = vtkImageGradient()
gradient.SetInputConnection(cast.GetOutputPort())
gradient.SetDimensionality(3)
gradient.Update()
forces = gradient.GetOutput().GetPointData().GetScalars()
check(forces.GetNumberOfComponents() == 3, "the force array has 3 components")
largest = forces.GetMaxNorm()
check(largest > 0.0, "the force field is not zero")

sphere = vtkSphereSource()
sphere.SetCenter(*CENTER)
sphere.SetRadius(11.0)
sphere.SetThetaResolution(24)
sphere.SetPhiResolution(16)
sphere.Update()

deformable = edmodel.vtkDeformableMesh()
deformable.SetInputConnection(sphere.GetOutputPort())
deformable.SetForceImageConnection(gradient.GetOutputPort())
# The gradient's 3-component array is the image's scalars, not its vectors.
deformable.SetInputArrayToProcess(0, 1, 0, 0, forces.GetName())  # 0: point data
# Largest external displacement of half a voxel per iteration.
deformable.SetScaleFactor(0.5 / largest)
deformable.SetNumberOfIterations(150)
deformable.Update()
output = deformable.GetOutput()
before = mean_distance(sphere.GetOutput())
after = mean_distance(output)
print("mean distance to the ellipsoid: %.3f voxel before, %.3f after" % (before, after))
check(output.GetNumberOfPoints() == sphere.GetOutput().GetNumberOfPoints(), "the output has the input's points")
check(output.GetNumberOfPolys() == sphere.GetOutput().GetNumberOfPolys(), "the output has the input's triangles")
check(deformable.GetCurrentIteration() == 150, "150 iterations run")
check(before > 0.5, "the sphere starts off the ellipsoid (%.3f)" % before)
check(after < 0.25, "the mesh ends on the ellipsoid (%.3f < 0.25 voxel)" % after)
check(output.GetPointData().GetArray("DisplacementMagnitude") is not None, "diagnostics are point arrays")

# Step by step with IterateFromZero off: the same mesh.
stepwise = edmodel.vtkDeformableMesh()
stepwise.SetInputConnection(0, sphere.GetOutputPort())
stepwise.SetInputConnection(1, gradient.GetOutputPort())
stepwise.SetInputArrayToProcess(0, 1, 0, 0, forces.GetName())
stepwise.SetScaleFactor(0.5 / largest)
stepwise.IterateFromZeroOff()
for n in range(0, 151, 10):
    stepwise.SetNumberOfIterations(n)
    stepwise.Update()
check(stepwise.GetCurrentIteration() == 150, "step by step reaches iteration 150")
check(points(stepwise.GetOutput()) == points(output), "step by step gives the same mesh as one update")

# A missing force image: an error and an empty output.
errors = []
broken = edmodel.vtkDeformableMesh()
broken.AddObserver(vtkCommand.ErrorEvent, lambda caller, event: errors.append(event))
broken.SetInputConnection(sphere.GetOutputPort())
broken.SetNumberOfIterations(3)
broken.Update()
check(len(errors) >= 1 and broken.GetOutput().GetNumberOfPoints() == 0, "no force image: error, empty output")

# The Brownian warp and the time series writer.
warp = edmodel.vtkPolyDataIterativeWarp()
warp.SetInputConnection(sphere.GetOutputPort())
warp.SetStepLength(0.1)
warp.SetSeed(5)
with tempfile.TemporaryDirectory() as directory:
    writer = edmodel.vtkIterationSeriesWriter()
    writer.SetAlgorithm(warp)
    writer.SetFileName(os.path.join(directory, "warp.pvd"))
    writer.SetInterval(5)
    writer.SetNumberOfIterations(12)
    check(writer.Write() == 1, "the series is written")
    written = [writer.GetWrittenIteration(k) for k in range(writer.GetNumberOfWrittenFiles())]
    check(written == [0, 5, 10, 12], "iterations 0, 5, 10 and 12 written (%s)" % written)
    check(all(os.path.exists(writer.GetWrittenFileName(k)) for k in range(4)), "the .vtp files exist")
    with open(os.path.join(directory, "warp.pvd")) as collection:
        text = collection.read()
    check(text.count("<DataSet ") == 4 and 'file="warp_000012.vtp"' in text, "the .pvd lists the files")

print("edmodel deformation test passed")
