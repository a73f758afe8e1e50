# Segments a real scan with edmodel's defaults and scores the surface against
# a reference segmentation (edmScore): fails when edmodel fails or when the
# Dice or the mean boundary distance misses its limit.
# -DEDMODEL= -DSCORE= -DIMAGE= -DREFERENCE= -DSPHERE=X,Y,Z,R -DOUTPUT= -DMIN_DICE= -DMAX_MEAN=
file(REMOVE "${OUTPUT}")
execute_process(COMMAND ${EDMODEL} segment --image ${IMAGE} --init-sphere ${SPHERE} --output ${OUTPUT}
  RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
message(STATUS "${err}${out}")
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "edmodel exited with ${rc}")
endif()
execute_process(COMMAND ${SCORE} score ${OUTPUT} ${REFERENCE} --min-dice ${MIN_DICE} --max-mean ${MAX_MEAN}
  RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
message(STATUS "${out}${err}")
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "below the limits (Dice >= ${MIN_DICE}, mean distance <= ${MAX_MEAN} mm)")
endif()
