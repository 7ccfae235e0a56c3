# `cmake --install` and two Debian packages (cpack -G DEB), one per side:
#   pixyslam-robot    what runs on the robot, no GUI library (OpenCV core,
#                     imgproc, videoio for the camera only): the bridges, the
#                     estimator, the logger, the launcher, the inspection and
#                     playback tools, the simulator, the Foxglove bridge; config/ as /etc/pixyslam
#                     (conffiles), /etc/default/pixyslam, the robot unit, the
#                     pixyslam system user (maintainer scripts), the docs.
#   pixyslam-station  the laptop's extras, depending on pixyslam-robot: map_view
#                     (OpenCV highgui), the map optimiser (Ceres), slam_offline,
#                     pixyslam_calibrate, the station unit.
# Runtime dependencies come from dpkg-shlibdeps, per package.
#
# The programs keep their build names in one private folder, lib/pixyslam/bin
# (the launcher starts its siblings from its own folder), and are on the PATH
# as bin/pixyslam-NAME symlinks: no name can clash with another package's
# (a plain /usr/bin/logger is bsdutils', an Essential package).
include(GNUInstallDirs)

set(pixyslam_robot_programs
  encoder_bridge pixy_bridge slam_estimator logger robot_sim sim_evaluator
  pixyslam_launch pixyslam_spy pixyslam_log pixyslam_play)
if(TARGET foxglove_bridge)
  list(APPEND pixyslam_robot_programs foxglove_bridge)
endif()
set(pixyslam_station_programs slam_offline pixyslam_calibrate dataset_bridge fleet_map)
foreach(optional map_view map_optimizer)
  if(TARGET ${optional})
    list(APPEND pixyslam_station_programs ${optional})
  endif()
endforeach()
set(PIXYSLAM_PROGRAM_DIR lib/pixyslam/bin)
foreach(component robot station)
  install(TARGETS ${pixyslam_${component}_programs} RUNTIME DESTINATION ${PIXYSLAM_PROGRAM_DIR} COMPONENT ${component})
  # bin/pixyslam-NAME -> ../lib/pixyslam/bin/NAME, '_' as '-', without a doubled
  # prefix (pixyslam_launch -> pixyslam-launch, slam_estimator -> pixyslam-slam-estimator).
  foreach(program IN LISTS pixyslam_${component}_programs)
    string(REGEX REPLACE "^pixyslam_" "" short ${program})
    string(REPLACE "_" "-" short ${short})
    install(CODE "
      set(bin \"\$ENV{DESTDIR}\${CMAKE_INSTALL_PREFIX}/${CMAKE_INSTALL_BINDIR}\")
      file(RELATIVE_PATH target \"\${bin}\" \"\$ENV{DESTDIR}\${CMAKE_INSTALL_PREFIX}/${PIXYSLAM_PROGRAM_DIR}/${program}\")
      file(MAKE_DIRECTORY \"\${bin}\")
      file(CREATE_LINK \"\${target}\" \"\${bin}/pixyslam-${short}\" SYMBOLIC)
      list(APPEND CMAKE_INSTALL_MANIFEST_FILES \"\${bin}/pixyslam-${short}\")
      message(STATUS \"Installing: \${bin}/pixyslam-${short} -> \${target}\")" COMPONENT ${component})
  endforeach()
endforeach()
# Run by pixy_bridge in its place when a camera is wanted (components/pixy_bridge/main.cpp):
# beside it, without a bin/ link of its own.
if(TARGET pixy_bridge_camera)
  install(TARGETS pixy_bridge_camera RUNTIME DESTINATION ${PIXYSLAM_PROGRAM_DIR} COMPONENT robot)
endif()
# Configuration lives in /etc whatever the prefix (the systemd units read it there).
set(PIXYSLAM_SYSCONFDIR /etc CACHE PATH "Where config/ is installed (as pixyslam/)")
install(DIRECTORY ${PROJECT_SOURCE_DIR}/config/ DESTINATION ${PIXYSLAM_SYSCONFDIR}/pixyslam COMPONENT robot)
install(FILES ${PROJECT_SOURCE_DIR}/packaging/default/pixyslam DESTINATION ${PIXYSLAM_SYSCONFDIR}/default COMPONENT robot)
foreach(component robot station)
  install(FILES ${PROJECT_SOURCE_DIR}/packaging/systemd/pixyslam-${component}.service
          DESTINATION lib/systemd/system COMPONENT ${component})
endforeach()
set(CMAKE_INSTALL_DOCDIR ${CMAKE_INSTALL_DATAROOTDIR}/doc/pixyslam-robot)
install(FILES ${PROJECT_SOURCE_DIR}/README.md DESTINATION ${CMAKE_INSTALL_DOCDIR} COMPONENT robot)
install(DIRECTORY ${PROJECT_SOURCE_DIR}/docs/ DESTINATION ${CMAKE_INSTALL_DOCDIR}/docs COMPONENT robot)

set(CPACK_GENERATOR DEB)
set(CPACK_DEB_COMPONENT_INSTALL ON)
set(CPACK_COMPONENTS_ALL robot station)
set(CPACK_PACKAGE_NAME pixyslam)
set(CPACK_PACKAGE_VERSION ${PROJECT_VERSION})
set(CPACK_PACKAGING_INSTALL_PREFIX /usr)
set(CPACK_PACKAGE_CONTACT "pixyslam maintainers <pixyslam@localhost>")
set(CPACK_DEBIAN_FILE_NAME DEB-DEFAULT)
set(CPACK_DEBIAN_PACKAGE_SHLIBDEPS ON)
set(CPACK_DEBIAN_PACKAGE_SECTION science)
set(CPACK_DEBIAN_PACKAGE_CONTROL_STRICT_PERMISSION ON)
set(CPACK_DEBIAN_ROBOT_PACKAGE_NAME pixyslam-robot)
string(CONCAT CPACK_COMPONENT_ROBOT_DESCRIPTION
  "FastSLAM 2.0 for a landmark-pole robot: the robot side over Fast DDS\n"
  "Encoder and Pixy bridges, the FastSLAM 2.0 estimator, the MCAP logger, the launcher,\n"
  "the Foxglove WebSocket bridge,\n"
  "inspection and playback tools and the simulator, with systemd unit; no GUI library.")
set(CPACK_DEBIAN_ROBOT_PACKAGE_DEPENDS "fastdds-tools, adduser")
# The single package of earlier versions held these files: replaced on upgrade.
set(CPACK_DEBIAN_ROBOT_PACKAGE_CONFLICTS pixyslam)
set(CPACK_DEBIAN_ROBOT_PACKAGE_REPLACES pixyslam)
set(CPACK_DEBIAN_STATION_PACKAGE_NAME pixyslam-station)
string(CONCAT CPACK_COMPONENT_STATION_DESCRIPTION
  "FastSLAM 2.0 for a landmark-pole robot: the station (laptop) side\n"
  "The map viewer, the background map optimiser (Ceres), the offline runner and the\n"
  "calibration tool, with systemd unit.")
set(CPACK_DEBIAN_STATION_PACKAGE_DEPENDS "pixyslam-robot (= ${PROJECT_VERSION})")
# Every file under /etc is a conffile: an upgrade keeps the user's edits.
file(GLOB_RECURSE pixyslam_config_files RELATIVE ${PROJECT_SOURCE_DIR}/config ${PROJECT_SOURCE_DIR}/config/*)
set(pixyslam_conffiles "${PIXYSLAM_SYSCONFDIR}/default/pixyslam\n")
foreach(f IN LISTS pixyslam_config_files)
  string(APPEND pixyslam_conffiles "${PIXYSLAM_SYSCONFDIR}/pixyslam/${f}\n")
endforeach()
file(WRITE ${PROJECT_BINARY_DIR}/debian/conffiles "${pixyslam_conffiles}")
# Maintainer scripts: the pixyslam system user (robot postinst), services
# stopped before removal (prerm), state, user and enablement links gone on purge (postrm).
set(robot_scripts ${PROJECT_SOURCE_DIR}/packaging/debian/robot)
set(station_scripts ${PROJECT_SOURCE_DIR}/packaging/debian/station)
foreach(component robot station)
  set(UNIT pixyslam-${component}.service)
  configure_file(${PROJECT_SOURCE_DIR}/packaging/debian/prerm.in ${PROJECT_BINARY_DIR}/debian/${component}/prerm
                 @ONLY FILE_PERMISSIONS OWNER_READ OWNER_WRITE OWNER_EXECUTE GROUP_READ GROUP_EXECUTE
                 WORLD_READ WORLD_EXECUTE)
endforeach()
set(CPACK_DEBIAN_ROBOT_PACKAGE_CONTROL_EXTRA ${PROJECT_BINARY_DIR}/debian/conffiles
  ${robot_scripts}/postinst ${PROJECT_BINARY_DIR}/debian/robot/prerm ${robot_scripts}/postrm)
set(CPACK_DEBIAN_STATION_PACKAGE_CONTROL_EXTRA
  ${station_scripts}/postinst ${PROJECT_BINARY_DIR}/debian/station/prerm ${station_scripts}/postrm)
include(CPack)
