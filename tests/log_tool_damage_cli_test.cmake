# ctest script (log_tool_damage_cli): pixyslam_log info / print / check on a
# complete, a not closed and two damaged MCAP files written by
# mcap_damage_fixture. Complete and not closed exit 0 (check: 1 for not closed
# unless --allow-recovered); damaged exits 1 and names the byte offset of the
# damage on stderr; print prints every message that could be read. A file that
# does not exist exits 1.
#   cmake -DFIXTURE=... -DLOG_TOOL=... -DWORK_DIR=... -P log_tool_damage_cli_test.cmake
cmake_minimum_required(VERSION 3.22)

file(REMOVE_RECURSE ${WORK_DIR})
file(MAKE_DIRECTORY ${WORK_DIR})
execute_process(COMMAND ${FIXTURE} ${WORK_DIR} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "mcap_damage_fixture: exit ${rc}\n${out}${err}")
endif()
include(${WORK_DIR}/expected.cmake)

# run(NAME STATUS ARGS...): runs pixyslam_log ARGS, expects exit STATUS; sets
# NAME_out and NAME_err in the caller.
function(run name status)
  execute_process(COMMAND ${LOG_TOOL} ${ARGN} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err TIMEOUT 60)
  if(NOT "${rc}" STREQUAL "${status}")
    message(FATAL_ERROR "pixyslam_log ${ARGN}: exit ${rc}, expected ${status}\nstdout:\n${out}\nstderr:\n${err}")
  endif()
  set(${name}_out "${out}" PARENT_SCOPE)
  set(${name}_err "${err}" PARENT_SCOPE)
endfunction()

function(expect_match what text regex)
  if(NOT "${text}" MATCHES "${regex}")
    message(FATAL_ERROR "${what}: does not match '${regex}':\n${text}")
  endif()
endfunction()

function(expect_no_match what text regex)
  if("${text}" MATCHES "${regex}")
    message(FATAL_ERROR "${what}: matches '${regex}' but should not:\n${text}")
  endif()
endfunction()

# expect_count(WHAT TEXT REGEX N): REGEX occurs exactly N times in TEXT.
function(expect_count what text regex n)
  string(REGEX MATCHALL "${regex}" found "${text}")
  list(LENGTH found count)
  if(NOT count EQUAL n)
    message(FATAL_ERROR "${what}: '${regex}' found ${count} times, expected ${n}")
  endif()
endfunction()

set(dir ${WORK_DIR})
set(odometry "\"topic\":\"pixyslam/odometry\"")

# Complete: exit 0, nothing on stderr, the status agrees with the summary line.
run(info_closed 0 info ${dir}/closed.mcap)
expect_match("info closed" "${info_closed_out}" "status: +complete \\(footer and summary present, no problems\\)")
expect_match("info closed" "${info_closed_out}" "summary: +yes \\(chunk index used\\), footer: yes")
expect_match("info closed" "${info_closed_out}" "messages: +${MESSAGES} ")
expect_match("info closed stderr" "x${info_closed_err}" "^x$")
run(info_unchunked 0 info ${dir}/unchunked.mcap)
expect_match("info unchunked" "${info_unchunked_out}" "status: +complete \\(footer and summary present, no problems\\)")
expect_match("info unchunked" "${info_unchunked_out}" "summary: +yes, footer: yes")
run(info_no_summary 0 info ${dir}/no_summary.mcap)
expect_match("info no summary" "${info_no_summary_out}" "status: +complete \\(footer present, no summary section, no problems\\)")
expect_match("info no summary" "${info_no_summary_out}" "summary: +none \\(the footer points at no summary\\), footer: yes")
expect_match("info no summary" "${info_no_summary_out}" "messages: +50 ")
run(print_closed 0 print ${dir}/closed.mcap --json)
expect_count("print closed" "${print_closed_out}" "${odometry}" ${MESSAGES})
expect_match("print closed stderr" "x${print_closed_err}" "^x$")
# --topics selects as pixyslam_play's does (names, globs, exclusions; --topic
# is its old name); a selection of nothing, or a name the file has no channel
# of, is an error naming the pattern.
run(print_glob 0 print ${dir}/closed.mcap --topics "pixyslam/*" --json)
expect_count("print --topics glob" "${print_glob_out}" "${odometry}" ${MESSAGES})
run(print_old_flag 0 print ${dir}/closed.mcap --topics pixyslam/odometry --json)
expect_count("print --topic" "${print_old_flag_out}" "${odometry}" ${MESSAGES})
run(print_none 1 print ${dir}/closed.mcap --topics "!pixyslam/odometry")
expect_match("print --topics excluding all" "${print_none_err}" "--topics '!pixyslam/odometry': ")
run(print_absent 1 print ${dir}/closed.mcap --topics pixyslam/map_state)
expect_match("print --topics absent" "${print_absent_err}" "--topics 'pixyslam/map_state': ")
# A name that is no topic of this project is a command-line error (2), as in echo, hz and record.
run(print_unknown 2 print ${dir}/closed.mcap --topics pixyslam/nope)
expect_match("print --topics unknown" "${print_unknown_err}" "--topics 'pixyslam/nope': ")
run(check_closed 0 check ${dir}/closed.mcap --expect pixyslam/odometry=${MESSAGES})

# Not closed (cut in a chunk): exit 0 for info and print, a note on stderr;
# check refuses it unless --allow-recovered.
run(info_cut 0 info ${dir}/not_closed.mcap)
expect_match("info not closed" "${info_cut_out}"
  "status: +RECOVERED, not closed \\(no footer; records intact up to offset ${CUT_CHUNK_OFFSET}, [0-9]+ bytes after it ignored\\)")
expect_match("info not closed" "${info_cut_out}" "summary: +no, footer: no")
expect_match("info not closed" "${info_cut_out}" "messages: +${MESSAGES_BEFORE_CUT} ")
expect_no_match("info not closed" "${info_cut_out}" "DAMAGED")
run(print_cut 0 print ${dir}/not_closed.mcap --json)
expect_count("print not closed" "${print_cut_out}" "${odometry}" ${MESSAGES_BEFORE_CUT})
expect_match("print not closed stderr" "${print_cut_err}" "not_closed.mcap: not closed \\(no footer; records intact up to offset ${CUT_CHUNK_OFFSET}")
run(check_cut 1 check ${dir}/not_closed.mcap)
run(check_cut_allowed 0 check ${dir}/not_closed.mcap --allow-recovered)

# One chunk's length field damaged: every message still read (its header and
# the chunk index give the length, its CRC checks it), but the file is
# damaged: exit 1 and the offset on stderr.
run(info_length 1 info ${dir}/damaged_length.mcap)
expect_match("info damaged length" "${info_length_out}" "status: +DAMAGED \\(first damage at offset ${DAMAGED_OFFSET}; ")
expect_match("info damaged length" "${info_length_out}" "summary: +yes \\(chunk index used\\), footer: yes")
expect_match("info damaged length" "${info_length_out}" "messages: +${MESSAGES} ")
expect_no_match("info damaged length" "${info_length_out}" "not closed|no footer")
expect_match("info damaged length stderr" "${info_length_err}" "damaged_length.mcap: damaged: first damage at offset ${DAMAGED_OFFSET}")
expect_match("info damaged length stderr" "${info_length_err}" "damaged_length.mcap: offset ${DAMAGED_OFFSET}: ")
run(print_length 1 print ${dir}/damaged_length.mcap --json)
expect_count("print damaged length" "${print_length_out}" "${odometry}" ${MESSAGES})
expect_match("print damaged length stderr" "${print_length_err}" "damaged_length.mcap: offset ${DAMAGED_OFFSET}: ")
run(check_length 1 check ${dir}/damaged_length.mcap)
expect_match("check damaged length" "${check_length_out}" "FAIL file: DAMAGED")
expect_match("check damaged length stderr" "${check_length_err}" "offset ${DAMAGED_OFFSET}: ")
run(check_length_allowed 0 check ${dir}/damaged_length.mcap --allow-recovered --expect pixyslam/odometry=${MESSAGES})

# Its records damaged too: that chunk is lost, every other one read.
math(EXPR survivors "${MESSAGES} - ${DAMAGED_CHUNK_MESSAGES}")
run(info_chunk 1 info ${dir}/damaged_chunk.mcap)
expect_match("info damaged chunk" "${info_chunk_out}" "messages: +${survivors} ")
expect_match("info damaged chunk stderr" "${info_chunk_err}" "offset ${DAMAGED_OFFSET}: Chunk rejected")
run(print_chunk 1 print ${dir}/damaged_chunk.mcap --json)
expect_count("print damaged chunk" "${print_chunk_out}" "${odometry}" ${survivors})
run(check_chunk 1 check ${dir}/damaged_chunk.mcap --allow-recovered)
expect_match("check damaged chunk" "${check_chunk_out}" "seq not exactly 1..N")

# A file that does not exist: 1 (input, not usage), naming it and the reason.
foreach(command info check print)
  run(missing_${command} 1 ${command} ${dir}/no_such.mcap)
  expect_match("${command} missing file" "${missing_${command}_err}" "no_such.mcap: cannot open: No such file or directory")
endforeach()
run(missing_compare 1 compare ${dir}/closed.mcap ${dir}/no_such.mcap --topic pixyslam/odometry)
expect_match("compare missing file" "${missing_compare_err}" "no_such.mcap: cannot open: No such file or directory")

message(STATUS "log_tool_damage_cli: all steps passed")
