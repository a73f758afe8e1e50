"""Explicit deformable models for VTK, computed by the ITK filters of
ExplicitDeformableModel.

Classes:
  vtkPolyDataIterativeWarp   Brownian random walk of the points (StepLength, Seed)
  vtkDeformableMesh          deformable surface pulled by a vector image (port 1), or
                             contours (lines, polylines) over a 2-D image (nx x ny x 1)
  vtkExternalForceField      the force image of a volume or a 2-D image
                             (grad |grad G_sigma * I|, GVF)
  vtkIterationSeriesWriter   every K-th iteration as .vtp plus a .pvd collection
  vtkIterativePolyDataAlgorithm  their base class (NumberOfIterations,
                             CurrentIteration, IterateFromZero)
"""

# The VTK modules the wrapped classes derive from, loaded first.
import vtkmodules.vtkCommonCore  # noqa: F401
import vtkmodules.vtkCommonDataModel  # noqa: F401
import vtkmodules.vtkCommonExecutionModel  # noqa: F401

from .ExplicitDeformableModelVTK import *  # noqa: F401,F403
