# Read by cpack for each generator (CPACK_PROJECT_CONFIG_FILE, packaging/CMakeLists.txt): things that
# depend on the install prefix cpack uses, which `cpack -D CPACK_INSTALL_PREFIX=…` may change after
# configuring.
if(CPACK_GENERATOR STREQUAL "DEB")
  if(CPACK_INSTALL_PREFIX STREQUAL "/usr")
    set(_rr_etc /etc)
  else()
    set(_rr_etc "${CPACK_INSTALL_PREFIX}/etc")
  endif()
  file(WRITE "${CPACK_RR_CONTROL_DIR}/conffiles" "${_rr_etc}/rr-gateway/gateway.yaml\n")
  set(CPACK_DEBIAN_PACKAGE_CONTROL_EXTRA ${CPACK_RR_MAINTAINER_SCRIPTS} "${CPACK_RR_CONTROL_DIR}/conffiles")
endif()
