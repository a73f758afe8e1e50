# edmodel demo: exit code 0 (accuracy good), the files it promises (the .pvd
# series when built with VTK), and the accuracy figures on stdout.
# Figure 1 (FIGURE: edmodel built with VTK rendering): demo-figure1.png
# exists and is not blank (CHECK_PNG: edmCheckPNG --quadrants; otherwise a
# PNG signature and a size check). Debian's VTK renders through X: the demo
# runs under XVFB_RUN (xvfb-run) when given, and once more without a display,
# where it must skip the figure with a one-line reason and still succeed.
cmake_minimum_required(VERSION 3.16)
file(REMOVE_RECURSE "${WORK}")

function(edm_run_demo output_dir)
  execute_process(COMMAND ${ARGN} ${EDMODEL} demo --output-dir ${output_dir} RESULT_VARIABLE rc OUTPUT_VARIABLE out
    ERROR_VARIABLE err)
  message(STATUS "${ARGN} edmodel demo:\n${out}")
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "edmodel demo exited with ${rc}\n${err}")
  endif()
  foreach(file demo-image.nii.gz demo-force.mha demo-sphere.vtk demo-mesh.vtk)
    if(NOT EXISTS ${output_dir}/${file})
      message(FATAL_ERROR "edmodel demo did not write ${file}")
    endif()
  endforeach()
  if(NOT out MATCHES "final mesh: +mean [0-9.e-]+ voxel, max [0-9.e-]+ voxel" OR NOT out MATCHES "accuracy good")
    message(FATAL_ERROR "edmodel demo did not report its accuracy")
  endif()
  file(GLOB leftovers LIST_DIRECTORIES true "${output_dir}/.edmodel-*")
  if(leftovers)
    message(FATAL_ERROR "edmodel demo left temporary files: ${leftovers}")
  endif()
  set(demo_out "${out}" PARENT_SCOPE)
endfunction()

function(edm_check_figure png)
  if(NOT EXISTS ${png})
    message(FATAL_ERROR "edmodel demo did not write ${png}")
  endif()
  if(CHECK_PNG)
    execute_process(COMMAND ${CHECK_PNG} ${png} --quadrants RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
    if(NOT rc EQUAL 0)
      message(FATAL_ERROR "${png} is blank or unreadable:\n${out}${err}")
    endif()
  else()
    file(READ ${png} signature LIMIT 8 HEX)
    file(SIZE ${png} size)
    if(NOT signature STREQUAL "89504e470d0a1a0a" OR size LESS 20000)
      message(FATAL_ERROR "${png} is not a PNG or is nearly empty (${size} bytes)")
    endif()
  endif()
  message(STATUS "${png}: not blank")
endfunction()

execute_process(COMMAND ${EDMODEL} --version OUTPUT_VARIABLE version)
set(figure_line "skipped [^\n]*demo-figure1.png \\(Figure 1\\): ")

# Without a display.
unset(ENV{DISPLAY})
edm_run_demo(${WORK}/out)
if(version MATCHES "with VTK" AND NOT EXISTS ${WORK}/out/series/demo.pvd)
  message(FATAL_ERROR "edmodel demo, built with VTK, did not write series/demo.pvd")
endif()
if(EXISTS ${WORK}/out/demo-figure1.png)
  # A VTK that renders without X (EGL, OSMesa).
  edm_check_figure(${WORK}/out/demo-figure1.png)
elseif(NOT demo_out MATCHES "${figure_line}[^\n]+")
  message(FATAL_ERROR "edmodel demo wrote no demo-figure1.png and did not say why")
endif()
if(FIGURE AND NOT EXISTS ${WORK}/out/demo-figure1.png AND NOT demo_out MATCHES "${figure_line}no X display")
  message(FATAL_ERROR "edmodel demo, without a display, did not give the missing display as the reason")
endif()

# With a display: Figure 1.
if(FIGURE AND XVFB_RUN)
  # Its own range of display numbers, and no server reset (see vtk/examples).
  edm_run_demo(${WORK}/xvfb ${XVFB_RUN} -a -n 150 -s "-screen 0 1280x1024x24 -noreset")
  if(demo_out MATCHES "skipped")
    message(FATAL_ERROR "edmodel demo under xvfb-run skipped Figure 1")
  endif()
  edm_check_figure(${WORK}/xvfb/demo-figure1.png)
elseif(FIGURE)
  message(STATUS "xvfb-run not found: Figure 1 of edmodel demo only checked without a display")
endif()
