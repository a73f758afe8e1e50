#!/usr/bin/python3
"""Distance between two surfaces (legacy .vtk, .vtp or .obj triangle meshes),
in both directions: from each vertex of one to the nearest point of the other
surface (exact point-to-triangle distances, VTK's vtkCellLocator), and the
mean, 95th percentile and maximum of each direction and of both together.

Usage: bench/surface-distance.py MESH_A MESH_B [--max-mean MM] [--max-p95 MM]
  prints "mean MM p95 MM p99 MM max MM, beyond 0.5 mm N of M vertices (A to B
  mean/p95/max, B to A mean/p95/max)";
  exit 1 when a given limit fails (both directions pooled).

Used for issue 16's check that 500 and 5000 iterations give the same surface
(README, "Real images"). Needs VTK's Python (Debian python3-vtk9).
"""
import sys

import vtk
from vtk.util.numpy_support import vtk_to_numpy
import numpy as np


def read(path):
    if path.endswith('.vtp'):
        reader = vtk.vtkXMLPolyDataReader()
    elif path.endswith('.obj'):
        reader = vtk.vtkOBJReader()
    else:
        reader = vtk.vtkPolyDataReader()
    reader.SetFileName(path)
    reader.Update()
    mesh = reader.GetOutput()
    if mesh.GetNumberOfPoints() == 0 or mesh.GetNumberOfCells() == 0:
        sys.exit('surface-distance: %s holds no surface' % path)
    return mesh


def distances(points_of, surface):
    locator = vtk.vtkCellLocator()
    locator.SetDataSet(surface)
    locator.BuildLocator()
    closest = [0.0, 0.0, 0.0]
    cell = vtk.reference(0)
    sub = vtk.reference(0)
    d2 = vtk.reference(0.0)
    points = vtk_to_numpy(points_of.GetPoints().GetData()).astype(float)
    out = np.empty(len(points))
    for i, p in enumerate(points):
        locator.FindClosestPoint(p, closest, cell, sub, d2)
        out[i] = float(d2) ** 0.5
    return out


def summary(d):
    return d.mean(), np.percentile(d, 95), d.max()


def main(argv):
    paths, limits, args = [], {}, argv[1:]
    while args:
        arg = args.pop(0)
        if arg in ('--max-mean', '--max-p95') and args:
            limits[arg] = float(args.pop(0))
        elif arg.startswith('--'):
            sys.exit('surface-distance: unknown option ' + arg)
        else:
            paths.append(arg)
    if len(paths) != 2:
        sys.exit(__doc__)
    a, b = read(paths[0]), read(paths[1])
    ab, ba = distances(a, b), distances(b, a)
    both = np.concatenate([ab, ba])
    mean, p95, top = summary(both)
    print('mean %.3f p95 %.3f p99 %.3f max %.3f, beyond 0.5 mm %d of %d vertices '
          '(A to B %.3f/%.3f/%.3f, B to A %.3f/%.3f/%.3f)' %
          ((mean, p95, np.percentile(both, 99), top, np.count_nonzero(both > 0.5), len(both)) + summary(ab) +
           summary(ba)))
    if limits.get('--max-mean', np.inf) < mean or limits.get('--max-p95', np.inf) < p95:
        return 1
    return 0


if __name__ == '__main__':
    sys.exit(main(sys.argv))
