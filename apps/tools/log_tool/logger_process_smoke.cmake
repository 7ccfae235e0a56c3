# ctest script (logger_process_smoke): the `logger` executable (also --topics)
# and pixyslam_log end to end. Arguments: LOGGER, LOG_TOOL, CONFIG (config/logger.yaml),
# RECORDING (a complete file made by test_logger), WORK_DIR.
cmake_minimum_required(VERSION 3.22)

function(expect_status what actual expected)
  if(NOT "${actual}" STREQUAL "${expected}")
    message(FATAL_ERROR "${what}: exit status ${actual}, expected ${expected}")
  endif()
endfunction()

function(expect_match what text regex)
  if(NOT "${text}" MATCHES "${regex}")
    message(FATAL_ERROR "${what}: output does not match '${regex}':\n${text}")
  endif()
endfunction()

file(REMOVE_RECURSE ${WORK_DIR})
file(MAKE_DIRECTORY ${WORK_DIR})

# 1. A config error exits 2 and names the file and the key.
set(bad ${WORK_DIR}/bad_logger.yaml)
file(WRITE ${bad} "logger:\n  output_file: x.mcap\n  flush_period_sec: 1\n")
execute_process(COMMAND ${LOGGER} --config ${bad} RESULT_VARIABLE rc ERROR_VARIABLE err OUTPUT_QUIET)
expect_status("logger with an unknown key" "${rc}" 2)
expect_match("logger with an unknown key" "${err}" "bad_logger.yaml: key 'logger.flush_period_sec'")

# 2. SIGINT after a few seconds: exit 0 and a complete (empty) file. The
#    shipped config on a DDS domain of its own (so that nothing else on this
#    machine is recorded), its profiles file by absolute path.
file(READ ${CONFIG} config_text)
string(RANDOM LENGTH 2 ALPHABET 0123456789 domain_suffix)
get_filename_component(config_dir ${CONFIG} DIRECTORY)
string(REPLACE "domain_id: 0" "domain_id: 1${domain_suffix}" config_text "${config_text}")
string(REPLACE "profiles_file: dds/" "profiles_file: ${config_dir}/dds/" config_text "${config_text}")
set(config ${WORK_DIR}/logger.yaml)
file(WRITE ${config} "${config_text}")
find_program(TIMEOUT timeout REQUIRED)
set(out ${WORK_DIR}/smoke.mcap)
execute_process(COMMAND ${TIMEOUT} --preserve-status -s INT 3 ${LOGGER} --config ${config} --out ${out} --verbose
  RESULT_VARIABLE rc OUTPUT_VARIABLE stdout ERROR_VARIABLE err)
expect_status("logger stopped by SIGINT (stderr: ${err})" "${rc}" 0)
expect_match("logger effective configuration" "${stdout}" "output_file: '${out}'")
expect_match("logger effective configuration" "${stdout}" "domain_id: 1[0-9][0-9]")
expect_match("logger counts" "${err}" "pixyslam/odometry: received 0, written 0, dropped 0, seq gaps 0")
execute_process(COMMAND ${LOG_TOOL} info ${out} RESULT_VARIABLE rc OUTPUT_VARIABLE info)
expect_status("pixyslam_log info on the logger's file" "${rc}" 0)
expect_match("pixyslam_log info on the logger's file" "${info}" "status: +complete")
expect_match("pixyslam_log info on the logger's file" "${info}" "schemas: +8")  # every topic of config/logger.yaml
execute_process(COMMAND ${LOG_TOOL} check ${out} --expect pixyslam/odometry=0 RESULT_VARIABLE rc OUTPUT_VARIABLE check)
expect_status("pixyslam_log check on the logger's empty file:\n${check}" "${rc}" 0)

# 2b. --topics records only those (two channels, two schemas); a bad pattern
#     is a usage error (exit 2) naming it.
set(two ${WORK_DIR}/two_topics.mcap)
execute_process(COMMAND ${TIMEOUT} --preserve-status -s INT 2 ${LOGGER} --config ${config} --out ${two} --verbose
  --topics pixyslam/odometry,pixyslam/map_state RESULT_VARIABLE rc OUTPUT_VARIABLE stdout ERROR_VARIABLE err)
expect_status("logger --topics (stderr: ${err})" "${rc}" 0)
expect_match("logger --topics effective configuration" "${stdout}" "topics: \\[pixyslam/odometry, pixyslam/map_state\\]")
execute_process(COMMAND ${LOG_TOOL} info ${two} RESULT_VARIABLE rc OUTPUT_VARIABLE info)
expect_match("pixyslam_log info on the two-topic file" "${info}" "schemas: +2")
expect_match("pixyslam_log info on the two-topic file" "${info}" "topics: +2")
execute_process(COMMAND ${LOGGER} --config ${config} --topics pixyslam/nope RESULT_VARIABLE rc ERROR_VARIABLE err OUTPUT_QUIET)
expect_status("logger --topics with an unknown topic" "${rc}" 2)
expect_match("logger --topics with an unknown topic" "${err}" "--topics: 'pixyslam/nope'")

# 3. A copy of the recording cut at 60 %: info reports the recovery, check
#    refuses it unless --allow-recovered (then the recovered prefix checks).
file(SIZE ${RECORDING} size)
math(EXPR cut "${size} * 6 / 10")
set(truncated ${WORK_DIR}/truncated.mcap)
execute_process(COMMAND head -c ${cut} ${RECORDING} OUTPUT_FILE ${truncated} RESULT_VARIABLE rc)
expect_status("head -c" "${rc}" 0)
execute_process(COMMAND ${LOG_TOOL} info ${truncated} RESULT_VARIABLE rc OUTPUT_VARIABLE info)
expect_status("pixyslam_log info on a truncated file" "${rc}" 0)
expect_match("pixyslam_log info on a truncated file" "${info}" "RECOVERED")
expect_match("pixyslam_log info on a truncated file" "${info}" "ignored at end")
execute_process(COMMAND ${LOG_TOOL} check ${truncated} RESULT_VARIABLE rc OUTPUT_VARIABLE check)
expect_status("pixyslam_log check on a truncated file:\n${check}" "${rc}" 1)
execute_process(COMMAND ${LOG_TOOL} check ${truncated} --allow-recovered RESULT_VARIABLE rc OUTPUT_VARIABLE check)
expect_status("pixyslam_log check --allow-recovered on a truncated file:\n${check}" "${rc}" 0)
message(STATUS "logger_process_smoke: all steps passed")
