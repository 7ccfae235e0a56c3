# Runs `slam_offline hardware` (robot_sim's bytes through the bridges' parsers,
# offline) with two filter seeds: --seed is the filter's, so both runs decode the
# same bytes (same frames, same dead reckoning) and differ in the filter's
# trajectory; each ATE is under the demo's 0.13 m. A section the estimator's
# file does not have is a config error (exit 2) naming it.
file(REMOVE_RECURSE "${OUT}")
foreach(seed 1 2)
  execute_process(COMMAND "${RUNNER}" hardware --config "${CONFIG_DIR}/slam_estimator.yaml"
    --sim-config "${CONFIG_DIR}/robot_sim.yaml" --out-dir "${OUT}/seed${seed}" --seed ${seed}
    OUTPUT_VARIABLE out ERROR_VARIABLE err RESULT_VARIABLE rc)
  message("${out}${err}")
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "slam_offline hardware --seed ${seed} exited with ${rc}")
  endif()
  string(REGEX MATCH "pose ATE RMSE +([0-9.]+) m +\\(dead reckoning ([0-9.]+) m\\)" line "${out}")
  set(ate_${seed} "${CMAKE_MATCH_1}")
  set(dead_reckoning_${seed} "${CMAKE_MATCH_2}")
  string(REGEX MATCH "emulated hardware, [0-9]+ visible poles, [0-9]+ frames with detections" bytes_${seed} "${out}")
  if(NOT ate_${seed} OR ate_${seed} GREATER_EQUAL 0.13)
    message(FATAL_ERROR "--seed ${seed}: pose ATE RMSE '${ate_${seed}}' is not under 0.13 m")
  endif()
  file(READ "${OUT}/seed${seed}/trajectory.csv" trajectory_${seed})
endforeach()
if(NOT bytes_1 OR NOT bytes_1 STREQUAL bytes_2 OR NOT dead_reckoning_1 STREQUAL dead_reckoning_2)
  message(FATAL_ERROR "--seed changed the hardware's bytes: '${bytes_1}' / '${bytes_2}', dead reckoning "
                      "${dead_reckoning_1} / ${dead_reckoning_2} m")
endif()
if(trajectory_1 STREQUAL trajectory_2)
  message(FATAL_ERROR "--seed 1 and --seed 2 gave the same trajectory: the filter's seed was not used")
endif()
file(READ "${CONFIG_DIR}/slam_estimator.yaml" estimator_text)
file(WRITE "${OUT}/unknown_section.yaml" "${estimator_text}\nbogus_section: 1\n")
execute_process(COMMAND "${RUNNER}" hardware --config "${OUT}/unknown_section.yaml"
  --sim-config "${CONFIG_DIR}/robot_sim.yaml" --out-dir "${OUT}/bad"
  OUTPUT_VARIABLE out ERROR_VARIABLE err RESULT_VARIABLE rc)
if(NOT rc EQUAL 2 OR NOT err MATCHES "bogus_section")
  message(FATAL_ERROR "an unknown section: exit ${rc}, '${err}' (expected 2 naming it)")
endif()
