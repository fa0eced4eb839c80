# Defines rr_usb_emulator (usb_emulator.cpp: the umockdev USB device emulator) when umockdev-1.0 and
# the rr+usb host transport are available; included by test/usb and bench/.
if(NOT TARGET rr_usb_emulator AND TARGET rr_usb_host)
  find_package(PkgConfig QUIET)
  if(PkgConfig_FOUND)
    pkg_check_modules(UMOCKDEV QUIET IMPORTED_TARGET umockdev-1.0)
  endif()
  if(UMOCKDEV_FOUND)
    add_library(rr_usb_emulator STATIC ${CMAKE_CURRENT_LIST_DIR}/usb_emulator.cpp)
    target_link_libraries(rr_usb_emulator PUBLIC rr_server PkgConfig::UMOCKDEV)
  endif()
endif()
