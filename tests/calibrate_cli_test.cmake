# ctest calibrate_cli: pixyslam_calibrate camera on poles measured with a
# camera of focal length 2.95 mm (blocks rounded to whole pixels): the fitted
# value lands in the written config, which the bridge's reader accepts; a bad
# row exits 2 naming file and line. Arguments: CALIBRATE, CONFIG, WORK_DIR.
cmake_minimum_required(VERSION 3.22)
file(REMOVE_RECURSE ${WORK_DIR})
file(MAKE_DIRECTORY ${WORK_DIR})
set(csv "distance_m,height_px\n")
foreach(cm 40 60 80 100 150 200 250 300)
  # Eq. 5: h = f h_r I_h / (S_h r) = 2.95 * 0.08 * 200 / (2.43 r)
  math(EXPR h_x1000 "2950 * 80 * 200 * 100 / (2430 * ${cm})")
  math(EXPR h "(${h_x1000} + 500) / 1000")
  math(EXPR m "${cm} / 100")
  math(EXPR rest "${cm} % 100")
  string(APPEND csv "${m}.${rest},${h}\n")
endforeach()
file(WRITE ${WORK_DIR}/poles.csv "${csv}")
execute_process(COMMAND ${CALIBRATE} camera --samples ${WORK_DIR}/poles.csv --config ${CONFIG}/pixy_bridge.yaml
                        --out ${WORK_DIR}/pixy_bridge.yaml
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "calibrate camera failed (${rc}):\n${out}${err}")
endif()
message(STATUS "${out}")
file(READ ${WORK_DIR}/pixy_bridge.yaml written)
if(NOT written MATCHES "focal_length_mm: 2\\.9[3-7][0-9]* +# f\n")
  message(FATAL_ERROR "the written config has no fitted focal length near 2.95:\n${written}")
endif()
file(WRITE ${WORK_DIR}/bad.csv "distance_m,height_px\n1.0,30\n1.5,twenty\n")
execute_process(COMMAND ${CALIBRATE} camera --samples ${WORK_DIR}/bad.csv --config ${CONFIG}/pixy_bridge.yaml
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 2 OR NOT err MATCHES "bad.csv:3: height_px 'twenty' is not a number")
  message(FATAL_ERROR "a bad row should exit 2 naming bad.csv:3, got ${rc}:\n${err}")
endif()
# expect(CODE REGEX args...): exit status CODE, stderr matching REGEX.
function(expect code pattern)
  execute_process(COMMAND ${CALIBRATE} ${ARGN} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc STREQUAL "${code}" OR NOT err MATCHES "${pattern}")
    message(FATAL_ERROR "pixyslam_calibrate ${ARGN}: exit ${rc}, expected ${code} and '${pattern}':\n${err}")
  endif()
endfunction()
set(pixy ${CONFIG}/pixy_bridge.yaml)
expect(2 "give one of --samples and --images" camera --config ${pixy})
expect(2 "give one of --samples and --images" camera --config ${pixy} --samples ${WORK_DIR}/poles.csv
       --images ${WORK_DIR}/poles.csv)
expect(2 "--config: At Most 1" camera --config ${pixy} --config ${pixy} --samples ${WORK_DIR}/poles.csv)
expect(2 "unknown option --confg" camera --confg ${pixy} --samples ${WORK_DIR}/poles.csv)
# A measurement file is input, not configuration: 1, with the OS reason.
expect(1 "nope.csv: cannot open: No such file or directory" camera --config ${pixy} --samples ${WORK_DIR}/nope.csv)
# --out in a folder that is not there: refused before the calibration runs.
expect(2 "--out ${WORK_DIR}/no_folder/pixy.yaml: no folder '${WORK_DIR}/no_folder'" camera --config ${pixy}
       --samples ${WORK_DIR}/poles.csv --out ${WORK_DIR}/no_folder/pixy.yaml)
# noise: --dataset, and --mrclam, its old name, still accepted.
foreach(flag --dataset --mrclam)
  expect(1 "data set folder not found: ${WORK_DIR}/no_data" noise ${flag} ${WORK_DIR}/no_data --robot 1
         --config ${CONFIG}/slam_new_robot.yaml --out ${WORK_DIR}/noise.yaml)
endforeach()
