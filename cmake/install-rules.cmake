# Installs the libraries (awcc::core, awcc::io, awcc::awcc, synth::synth,
# correction::correction, study::study), their headers, the pdp tool and one
# CMake package "pdp": consumers write find_package(pdp CONFIG REQUIRED) and
# link what they use. Headers under awcc/detail/ are the libraries' own and not installed.
include(CMakePackageConfigHelpers)

set(PDP_INSTALL_CMAKEDIR "${CMAKE_INSTALL_LIBDIR}/cmake/pdp")

foreach(target awcc_core awcc_io awcc synth correction study)
  install(TARGETS ${target} EXPORT ${target}Targets
    ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
    LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR}
    RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR}
    INCLUDES DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
endforeach()
install(DIRECTORY libcore/include/awcc libio/include/awcc libawcc/include/awcc DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}
  PATTERN detail EXCLUDE)
install(FILES ${PROJECT_BINARY_DIR}/generated/awcc/version.hpp
  DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/awcc)
install(DIRECTORY libsynth/include/synth libcorrection/include/correction libstudy/include/study
  DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})

install(EXPORT awcc_coreTargets NAMESPACE awcc:: DESTINATION ${PDP_INSTALL_CMAKEDIR})
install(EXPORT awcc_ioTargets NAMESPACE awcc:: DESTINATION ${PDP_INSTALL_CMAKEDIR})
install(EXPORT awccTargets NAMESPACE awcc:: DESTINATION ${PDP_INSTALL_CMAKEDIR})
install(EXPORT synthTargets NAMESPACE synth:: DESTINATION ${PDP_INSTALL_CMAKEDIR})
install(EXPORT correctionTargets NAMESPACE correction:: DESTINATION ${PDP_INSTALL_CMAKEDIR})
install(EXPORT studyTargets NAMESPACE study:: DESTINATION ${PDP_INSTALL_CMAKEDIR})

configure_package_config_file(cmake/pdpConfig.cmake.in
  ${PROJECT_BINARY_DIR}/pdpConfig.cmake
  INSTALL_DESTINATION ${PDP_INSTALL_CMAKEDIR})
write_basic_package_version_file(${PROJECT_BINARY_DIR}/pdpConfigVersion.cmake
  COMPATIBILITY SameMinorVersion)
install(FILES ${PROJECT_BINARY_DIR}/pdpConfig.cmake ${PROJECT_BINARY_DIR}/pdpConfigVersion.cmake
  DESTINATION ${PDP_INSTALL_CMAKEDIR})

if(PDP_BUILD_TOOLS)
  install(TARGETS pdp RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
endif()
