# Script mode: removes the `registerXTypes();` call that fastddsgen 2.3 puts in
# every constructor of a generated type (FILES: its <stem>.cxx files). The
# TypeObjects are registered once per participant instead (dds/participant.cpp,
# dds/endpoints.h); in constructors the call cost 4.5 us per msg::Pose2D (of
# which a MapState holds up to 512), more than the message itself.
cmake_minimum_required(VERSION 3.22)
foreach(file ${FILES})
  file(READ ${file} text)
  string(REGEX REPLACE "\n[ \t]*// Just to register all known types\n[ \t]*register[A-Za-z0-9_]*Types\\(\\);" "" stripped "${text}")
  if(NOT stripped STREQUAL text)
    file(WRITE ${file} "${stripped}")
  endif()
endforeach()
