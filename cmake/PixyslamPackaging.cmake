# `cmake --install` and a Debian package (cpack -G DEB): the programs, config/
# as /etc/pixyslam (conffiles), systemd units for the robot and station sides,
# /etc/default/pixyslam for their DDS deployment. Runtime dependencies come
# from dpkg-shlibdeps.
#
# The programs keep their build names in one private folder, lib/pixyslam/bin
# (the launcher starts its siblings from its own folder), and are on the PATH
# as bin/pixyslam-NAME symlinks: no name can clash with another package's
# (a plain /usr/bin/logger is bsdutils', an Essential package).
include(GNUInstallDirs)

set(pixyslam_programs
  encoder_bridge pixy_bridge slam_estimator logger robot_sim sim_evaluator slam_offline
  pixyslam_launch pixyslam_spy pixyslam_log pixyslam_play pixyslam_calibrate)
if(TARGET map_view)
  list(APPEND pixyslam_programs map_view)
endif()
if(TARGET map_optimizer)
  list(APPEND pixyslam_programs map_optimizer)
endif()
set(PIXYSLAM_PROGRAM_DIR lib/pixyslam/bin)
install(TARGETS ${pixyslam_programs} RUNTIME DESTINATION ${PIXYSLAM_PROGRAM_DIR})
# bin/pixyslam-NAME -> ../lib/pixyslam/bin/NAME, '_' as '-', without a doubled
# prefix (pixyslam_launch -> pixyslam-launch, slam_estimator -> pixyslam-slam-estimator).
foreach(program IN LISTS pixyslam_programs)
  string(REGEX REPLACE "^pixyslam_" "" short ${program})
  string(REPLACE "_" "-" short ${short})
  install(CODE "
    set(bin \"\$ENV{DESTDIR}\${CMAKE_INSTALL_PREFIX}/${CMAKE_INSTALL_BINDIR}\")
    file(RELATIVE_PATH target \"\${bin}\" \"\$ENV{DESTDIR}\${CMAKE_INSTALL_PREFIX}/${PIXYSLAM_PROGRAM_DIR}/${program}\")
    file(MAKE_DIRECTORY \"\${bin}\")
    file(CREATE_LINK \"\${target}\" \"\${bin}/pixyslam-${short}\" SYMBOLIC)
    list(APPEND CMAKE_INSTALL_MANIFEST_FILES \"\${bin}/pixyslam-${short}\")
    message(STATUS \"Installing: \${bin}/pixyslam-${short} -> \${target}\")")
endforeach()
# Configuration lives in /etc whatever the prefix (the systemd units read it there).
set(PIXYSLAM_SYSCONFDIR /etc CACHE PATH "Where config/ is installed (as pixyslam/)")
install(DIRECTORY ${PROJECT_SOURCE_DIR}/config/ DESTINATION ${PIXYSLAM_SYSCONFDIR}/pixyslam)
install(FILES ${PROJECT_SOURCE_DIR}/packaging/default/pixyslam DESTINATION ${PIXYSLAM_SYSCONFDIR}/default)
install(FILES ${PROJECT_SOURCE_DIR}/packaging/systemd/pixyslam-robot.service
              ${PROJECT_SOURCE_DIR}/packaging/systemd/pixyslam-station.service
        DESTINATION lib/systemd/system)
install(FILES ${PROJECT_SOURCE_DIR}/README.md DESTINATION ${CMAKE_INSTALL_DOCDIR})
install(DIRECTORY ${PROJECT_SOURCE_DIR}/docs/ DESTINATION ${CMAKE_INSTALL_DOCDIR}/docs)

set(CPACK_GENERATOR DEB)
set(CPACK_PACKAGE_NAME pixyslam)
set(CPACK_PACKAGE_VERSION ${PROJECT_VERSION})
set(CPACK_PACKAGING_INSTALL_PREFIX /usr)
set(CPACK_PACKAGE_DESCRIPTION_SUMMARY "FastSLAM 2.0 for a landmark-pole robot: bridges, estimator, logger over Fast DDS")
set(CPACK_PACKAGE_CONTACT "pixyslam maintainers <pixyslam@localhost>")
set(CPACK_DEBIAN_FILE_NAME DEB-DEFAULT)
set(CPACK_DEBIAN_PACKAGE_SHLIBDEPS ON)
set(CPACK_DEBIAN_PACKAGE_SECTION science)
# Every file under /etc is a conffile: an upgrade keeps the user's edits.
file(GLOB_RECURSE pixyslam_config_files RELATIVE ${PROJECT_SOURCE_DIR}/config ${PROJECT_SOURCE_DIR}/config/*)
set(pixyslam_conffiles "${PIXYSLAM_SYSCONFDIR}/default/pixyslam\n")
foreach(f IN LISTS pixyslam_config_files)
  string(APPEND pixyslam_conffiles "${PIXYSLAM_SYSCONFDIR}/pixyslam/${f}\n")
endforeach()
file(WRITE ${PROJECT_BINARY_DIR}/debian/conffiles "${pixyslam_conffiles}")
# Maintainer scripts: the pixyslam system user (postinst), services stopped
# before removal (prerm), state and user gone on purge (postrm).
set(CPACK_DEBIAN_PACKAGE_CONTROL_EXTRA ${PROJECT_BINARY_DIR}/debian/conffiles
  ${PROJECT_SOURCE_DIR}/packaging/debian/postinst ${PROJECT_SOURCE_DIR}/packaging/debian/prerm
  ${PROJECT_SOURCE_DIR}/packaging/debian/postrm)
set(CPACK_DEBIAN_PACKAGE_CONTROL_STRICT_PERMISSION ON)
set(CPACK_DEBIAN_PACKAGE_DEPENDS "fastdds-tools, adduser")
include(CPack)
