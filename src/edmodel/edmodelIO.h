#ifndef edmodelIO_h
#define edmodelIO_h

// Image and mesh files for edmodel: reading with one-line errors, and writing
// through a temporary directory so that a failed run leaves no partial file.

#include "itkCovariantVector.h"
#include "itkImage.h"
#include "itkMesh.h"

#include <string>

namespace edm
{

using ImageType = itk::Image<float, 3>;
using ForceImageType = itk::Image<itk::CovariantVector<float, 3>, 3>;
/** Double coordinates: physical positions far from the origin keep their
 * precision. */
using MeshType = itk::Mesh<double, 3, itk::DefaultStaticMeshTraits<double, 3, 3, double, double>>;

/** Reads a 3-D image (a file ITK reads, or a directory holding a DICOM
 * series) as float. Throws Error (exit code 2) naming the problem: missing or
 * unreadable file, unknown format, a 2-D or 4-D image. */
ImageType::Pointer
ReadImage(const std::string & path);

/** Reads a surface mesh (.vtk, .obj, .off, .gii). \a option names the
 * command-line option in messages. Throws Error when the file is missing,
 * unreadable, of an unknown format or has no triangle or polygon. */
MeshType::Pointer
ReadMesh(const std::string & path, const std::string & option);

/** Number of triangles and polygons of a mesh. */
size_t
CountSurfaceCells(const MeshType * mesh);

/** Checks, before any computation, that \a path can take a mesh: a known
 * extension and an existing directory. Throws Error otherwise. */
void
CheckMeshOutputPath(const std::string & path, const std::string & option);

/** Same for an image. */
void
CheckImageOutputPath(const std::string & path, const std::string & option);

/** Writers: the file appears complete, or not at all. Throw Error (exit
 * code 2) when writing fails. */
void
WriteMesh(const MeshType * mesh, const std::string & path);
void
WriteImage(const ImageType * image, const std::string & path);
void
WriteImage(const ForceImageType * image, const std::string & path);

/** "a.b.c" -> ".c", "a.nii.gz" -> ".nii.gz", lower case. */
std::string
GetExtension(const std::string & path);

/** The first line of an exception's description, without trailing spaces. */
std::string
OneLine(const std::string & text);

} // namespace edm

#endif
