# Segments a real scan with edmodel's defaults and scores the surface against
# a reference segmentation (edmScore): fails when edmodel fails, when the
# Dice or the mean boundary distance misses its limit, or, unless EXTRA
# holds --allow-self-intersections, when the surface intersects itself.
# -DEDMODEL= -DSCORE= -DIMAGE= -DREFERENCE= -DSPHERE=X,Y,Z,R -DOUTPUT= -DMIN_DICE= -DMAX_MEAN= [-DEXTRA=a|b]
string(REPLACE "|" ";" EXTRA "${EXTRA}")
file(REMOVE "${OUTPUT}")
execute_process(COMMAND ${EDMODEL} segment --image ${IMAGE} --init-sphere ${SPHERE} ${EXTRA} --output ${OUTPUT}
  RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
message(STATUS "${err}${out}")
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "edmodel exited with ${rc}")
endif()
# The collision test (on by default) keeps the surface from intersecting
# itself (ch2bet without it, --allow-self-intersections: 70 intersecting
# pairs of triangles).
string(FIND "${EXTRA}" "--allow-self-intersections" allow)
if(allow EQUAL -1 AND NOT out MATCHES "surface quality: 0 intersecting pairs of triangles")
  message(FATAL_ERROR "the surface intersects itself, or edmodel gave no quality summary")
endif()
execute_process(COMMAND ${SCORE} score ${OUTPUT} ${REFERENCE} --min-dice ${MIN_DICE} --max-mean ${MAX_MEAN}
  RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
message(STATUS "${out}${err}")
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "below the limits (Dice >= ${MIN_DICE}, mean distance <= ${MAX_MEAN} mm)")
endif()

# Issue 16: the surface stops by itself, so 5 000 iterations per level give
# the surface of 500 (every level converges before 500 iterations; the same
# binary then writes the same bytes).
if(SAME_AT_5000)
  string(REGEX REPLACE "\\.vtk$" "-5000.vtk" long "${OUTPUT}")
  file(REMOVE "${long}")
  execute_process(COMMAND ${EDMODEL} segment --quiet --image ${IMAGE} --init-sphere ${SPHERE} ${EXTRA} --iterations 5000
    --output ${long} RESULT_VARIABLE rc ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "edmodel --iterations 5000 exited with ${rc}: ${err}")
  endif()
  execute_process(COMMAND ${CMAKE_COMMAND} -E compare_files ${OUTPUT} ${long} RESULT_VARIABLE rc)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "--iterations 5000 gave another surface than the default 500: ${long}")
  endif()
  message(STATUS "--iterations 5000 gives the same surface as 500, byte for byte")
endif()
