# pixyslam_add_idl_library(TARGET IDL_DIR DIR IDL_FILES a.idl ... [PLAIN_IDL_FILES c.idl ...])
#
# Generates C++ types, PubSubTypes and TypeObjects with fastddsgen (-typeobject)
# into the build tree at build time, and a static library TARGET of them linked
# to Fast DDS. The types' constructors do not re-register the TypeObjects
# (cmake/strip_type_registration.cmake): the participant registers them once. PLAIN_IDL_FILES get types and PubSubTypes only: fastddsgen 2.3's
# types re-register their TypeObjects in every constructor, which costs far
# more than the message itself for types built by the thousand (Foxglove's). Also generates <TARGET>_idl_text.cpp: each file's IDL with its
# includes inlined (an `omgidl` schema for MCAP), looked up by file stem.
find_program(FASTDDSGEN_EXECUTABLE fastddsgen REQUIRED)

function(pixyslam_add_idl_library target)
  cmake_parse_arguments(ARG "" "IDL_DIR" "IDL_FILES;PLAIN_IDL_FILES" ${ARGN})
  set(out_dir ${CMAKE_CURRENT_BINARY_DIR}/${target}_generated)
  set(tmp_dir ${CMAKE_CURRENT_BINARY_DIR}/${target}_fastddsgen_tmp)  # its preprocessed copies (else in /tmp)
  file(MAKE_DIRECTORY ${out_dir} ${tmp_dir})
  set(idl_paths "")
  set(generated "")
  foreach(idl ${ARG_IDL_FILES})
    get_filename_component(stem ${idl} NAME_WE)
    list(APPEND idl_paths ${ARG_IDL_DIR}/${idl})
    foreach(suffix "" PubSubTypes TypeObject)
      list(APPEND generated ${out_dir}/${stem}${suffix}.cxx ${out_dir}/${stem}${suffix}.h)
    endforeach()
  endforeach()
  set(type_sources "")
  foreach(idl ${ARG_IDL_FILES})
    get_filename_component(stem ${idl} NAME_WE)
    list(APPEND type_sources ${out_dir}/${stem}.cxx)
  endforeach()
  add_custom_command(
    OUTPUT ${generated}
    COMMAND ${FASTDDSGEN_EXECUTABLE} -typeobject -replace -t ${tmp_dir} -d ${out_dir} -I ${ARG_IDL_DIR} ${idl_paths}
    COMMAND ${CMAKE_COMMAND} "-DFILES=${type_sources}" -P ${PROJECT_SOURCE_DIR}/cmake/strip_type_registration.cmake
    DEPENDS ${idl_paths} ${PROJECT_SOURCE_DIR}/cmake/strip_type_registration.cmake
    WORKING_DIRECTORY ${out_dir}
    COMMENT "fastddsgen: ${ARG_IDL_FILES}"
    VERBATIM)
  if(ARG_PLAIN_IDL_FILES)
    set(plain_paths "")
    set(plain_generated "")
    foreach(idl ${ARG_PLAIN_IDL_FILES})
      get_filename_component(stem ${idl} NAME_WE)
      list(APPEND plain_paths ${ARG_IDL_DIR}/${idl})
      foreach(suffix "" PubSubTypes)
        list(APPEND plain_generated ${out_dir}/${stem}${suffix}.cxx ${out_dir}/${stem}${suffix}.h)
      endforeach()
    endforeach()
    add_custom_command(
      OUTPUT ${plain_generated}
      COMMAND ${FASTDDSGEN_EXECUTABLE} -replace -t ${tmp_dir} -d ${out_dir} -I ${ARG_IDL_DIR} ${plain_paths}
      DEPENDS ${plain_paths}
      WORKING_DIRECTORY ${out_dir}
      COMMENT "fastddsgen: ${ARG_PLAIN_IDL_FILES}"
      VERBATIM)
    list(APPEND generated ${plain_generated})
    list(APPEND idl_paths ${plain_paths})
  endif()

  set(text_cpp ${out_dir}/${target}_idl_text.cpp)
  add_custom_command(
    OUTPUT ${text_cpp}
    COMMAND ${CMAKE_COMMAND} -DIDL_DIR=${ARG_IDL_DIR} "-DIDL_FILES=${ARG_IDL_FILES};${ARG_PLAIN_IDL_FILES}"
            -DOUTPUT=${text_cpp} -P ${PROJECT_SOURCE_DIR}/cmake/embed_idl_text.cmake
    DEPENDS ${idl_paths} ${PROJECT_SOURCE_DIR}/cmake/embed_idl_text.cmake
    COMMENT "Embedding IDL text for ${target}"
    VERBATIM)

  list(FILTER generated INCLUDE REGEX "\\.cxx$")
  add_library(${target} STATIC ${generated} ${text_cpp})
  target_include_directories(${target} PUBLIC ${out_dir})
  target_link_libraries(${target} PUBLIC fastcdr fastrtps)
  target_compile_features(${target} PUBLIC cxx_std_17)
  # The generated files each parse the Fast DDS headers: compiled eight to a
  # unit, the library builds in 40 % of the CPU time (native 84 -> 33 s).
  set_target_properties(${target} PROPERTIES POSITION_INDEPENDENT_CODE ON UNITY_BUILD ON)
endfunction()
