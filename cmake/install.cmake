# `cmake --install build [--prefix DIR]`: the oalservo executable in bin/, the example
# configurations in share/oalservo/config/, and the libraries (base, detector, target, scene,
# servo, robots, calibration, io, loop, and eval's lines, rendered, recordings, campaigns) with their headers and a CMake package, so that
# another project can write
#
#   find_package(oalservo 0.1 REQUIRED)
#   target_link_libraries(my_node PRIVATE oal::detector oal::servo oal::loop)
#
# and include "detector/tracker.h", "servo/pose.h", "loop/servo_loop.h", ... as this
# repository does. The app library (YAML, command line) is the executable's own and is not
# installed.
include(CMakePackageConfigHelpers)

set(OAL_INSTALL_CMAKEDIR ${CMAKE_INSTALL_LIBDIR}/cmake/oalservo)
foreach(folder base detector target scene servo robots calibration io loop)
  set_target_properties(oal_${folder} PROPERTIES EXPORT_NAME ${folder})
  install(TARGETS oal_${folder} EXPORT oalservoTargets
          ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
          LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR})
  install(DIRECTORY ${PROJECT_SOURCE_DIR}/${folder}/
          DESTINATION ${OAL_INSTALL_INCLUDEDIR}/${folder}
          FILES_MATCHING PATTERN "*.h")
endforeach()
foreach(subject lines rendered recordings campaigns)
  set_target_properties(oal_eval_${subject} PROPERTIES EXPORT_NAME eval_${subject})
  install(TARGETS oal_eval_${subject} EXPORT oalservoTargets
          ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
          LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR})
endforeach()
install(DIRECTORY ${PROJECT_SOURCE_DIR}/eval/ DESTINATION ${OAL_INSTALL_INCLUDEDIR}/eval
        FILES_MATCHING PATTERN "*.h")
install(EXPORT oalservoTargets NAMESPACE oal:: DESTINATION ${OAL_INSTALL_CMAKEDIR})

configure_package_config_file(${PROJECT_SOURCE_DIR}/cmake/oalservoConfig.cmake.in
                              ${PROJECT_BINARY_DIR}/oalservoConfig.cmake
                              INSTALL_DESTINATION ${OAL_INSTALL_CMAKEDIR})
write_basic_package_version_file(${PROJECT_BINARY_DIR}/oalservoConfigVersion.cmake
                                 COMPATIBILITY SameMinorVersion)
install(FILES ${PROJECT_BINARY_DIR}/oalservoConfig.cmake
              ${PROJECT_BINARY_DIR}/oalservoConfigVersion.cmake
        DESTINATION ${OAL_INSTALL_CMAKEDIR})

install(TARGETS oalservo RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
install(DIRECTORY ${PROJECT_SOURCE_DIR}/config/ DESTINATION ${CMAKE_INSTALL_DATADIR}/oalservo/config)
install(FILES ${PROJECT_SOURCE_DIR}/README.md DESTINATION ${CMAKE_INSTALL_DOCDIR})
install(DIRECTORY ${PROJECT_SOURCE_DIR}/docs/ DESTINATION ${CMAKE_INSTALL_DOCDIR})
