# Runs `slam_offline sim` and checks its outputs: both CSV files with their
# headers, and a pose ATE RMSE under 0.15 m on the simulated world (dead reckoning: ~0.4 m).
file(REMOVE_RECURSE "${OUT}")
execute_process(COMMAND "${RUNNER}" sim --config "${CONFIG}" --out "${OUT}"
  OUTPUT_VARIABLE out ERROR_VARIABLE err RESULT_VARIABLE rc)
message("${out}${err}")
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "slam_offline exited with ${rc}")
endif()
file(STRINGS "${OUT}/trajectory.csv" traj LIMIT_COUNT 1)
file(STRINGS "${OUT}/landmarks.csv" lms LIMIT_COUNT 1)
if(NOT traj STREQUAL "t,x,y,theta" OR NOT lms STREQUAL "id,x,y,cov_xx,cov_xy,cov_yy")
  message(FATAL_ERROR "unexpected CSV headers: '${traj}' '${lms}'")
endif()
string(REGEX MATCH "pose ATE RMSE +([0-9.]+) m" _ "${out}")
if(NOT CMAKE_MATCH_1 OR CMAKE_MATCH_1 GREATER_EQUAL 0.15)
  message(FATAL_ERROR "pose ATE RMSE '${CMAKE_MATCH_1}' is not under 0.15 m")
endif()
