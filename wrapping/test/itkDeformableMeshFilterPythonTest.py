#!/usr/bin/env python3
"""ITK Python wrapping of ExplicitDeformableModel: the seed's case.

A sphere of radius 16 voxels (itk.RegularSphereMeshSource, resolution 4: 1026
points) in the centre of a 64^3 binary image of an ellipsoid of radii
(18, 14, 18) voxels centred at voxel (31, 31, 31); forces from
itk.ExternalForceImageFilter (sigma 1), itk.DeformableMeshFilter with
ScaleFactor 0.5 for 500 iterations, itk.Mesh[itk.F, 3] and a force image of
itk.CovariantVector[itk.F, 3]. Known answer, as in the C++ test
DeformableMeshFilter.SphereReachesTheEllipsoidInVoxelSpace: every point ends
within 0.5 voxel of the true surface, 0.15 voxel on average (exact Euclidean
distance to the ellipsoid, computed here independently of the module). It also
checks that there was something to do (the initial sphere is 2 voxels off
the surface on the axes) and that the other wrapped filters instantiate for these types.

Usage: python3 itkDeformableMeshFilterPythonTest.py (itk importable: an ITK
build tree's Wrapping/Generators/Python on PYTHONPATH, or an installed itk).
Exit status 0 when the known answer holds.
"""

import math
import sys

import itk

SIZE = 64
CENTER = (31.0, 31.0, 31.0)
RADII = (18.0, 14.0, 18.0)


def inside(p):
    return sum(((p[k] - CENTER[k]) / RADII[k]) ** 2 for k in range(3)) <= 1.0


def distance_to_surface(p):
    """Euclidean distance from p to the ellipsoid: bisection on the Lagrange
    multiplier t of the closest point, a_k^2 z_k / (t + a_k^2)."""
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
    closest = [min(a2[k] * z[k] / (t + a2[k]) if t + a2[k] > 0.0 else RADII[k], RADII[k]) for k in range(3)]
    return math.sqrt(sum((z[k] - closest[k]) ** 2 for k in range(3)))


def main():
    ImageType = itk.Image[itk.F, 3]
    ForceImageType = itk.Image[itk.CovariantVector[itk.F, 3], 3]
    MeshType = itk.Mesh[itk.F, 3]

    image = ImageType.New()
    image.SetRegions([SIZE, SIZE, SIZE])
    image.Allocate()
    image.FillBuffer(0.0)
    for k in range(SIZE):
        for j in range(SIZE):
            for i in range(SIZE):
                if inside((i, j, k)):
                    image.SetPixel([i, j, k], 255.0)

    forces = itk.ExternalForceImageFilter[ImageType, ForceImageType].New()
    forces.SetInput(image)
    forces.SetSigma(1.0)

    sphere = itk.RegularSphereMeshSource[MeshType].New()
    sphere.SetCenter(CENTER)
    sphere.SetScale([16.0, 16.0, 16.0])
    sphere.SetResolution(4)
    sphere.Update()
    initial = sphere.GetOutput()
    n = initial.GetNumberOfPoints()
    initial_max = max(distance_to_surface(initial.GetPoint(i)) for i in range(n))

    model = itk.DeformableMeshFilter[MeshType, ForceImageType].New()
    model.SetInput(initial)
    model.SetForceImage(forces.GetOutput())
    model.SetScaleFactor(0.5)
    model.SetNumberOfIterations(500)
    model.Update()
    output = model.GetOutput()

    distances = [distance_to_surface(output.GetPoint(i)) for i in range(output.GetNumberOfPoints())]
    mean = sum(distances) / len(distances)
    largest = max(distances)
    print(
        f"{itk.Version.GetITKVersion()}: {n} points, {model.GetCurrentIteration()} iterations; "
        f"distance to the ellipsoid: initial max {initial_max:.3f}, "
        f"final mean {mean:.4f} voxel, max {largest:.4f} voxel"
    )

    # The other wrapped classes, for the same types.
    brownian = itk.BrownianMeshFilter[MeshType].New()
    brownian.SetInput(initial)
    brownian.SetNumberOfIterations(1)
    brownian.Update()
    iterative = itk.IterativeMeshFilter[MeshType, MeshType]
    assert model.GetNameOfClass() == "DeformableMeshFilter"
    assert isinstance(model, iterative), "DeformableMeshFilter is not an IterativeMeshFilter in Python"

    failures = []
    if output.GetNumberOfPoints() != n:
        failures.append(f"{output.GetNumberOfPoints()} output points for {n} input points")
    if initial_max < 1.5:
        failures.append(f"the initial sphere is already within {initial_max} voxel: nothing is tested")
    if mean > 0.15:
        failures.append(f"mean distance {mean} > 0.15 voxel")
    if largest > 0.5:
        failures.append(f"max distance {largest} > 0.5 voxel")
    for failure in failures:
        print("FAIL:", failure)
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
