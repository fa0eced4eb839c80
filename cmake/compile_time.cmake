# What keeps the cold build inside CI's budget (issue 45; docs/development.md "CI time"), applied once
# every target exists. Included at the end of the top-level CMakeLists.txt.

# Every library and program target under a directory, recursively.
function(rr_collect_targets dir out)
  get_property(targets DIRECTORY ${dir} PROPERTY BUILDSYSTEM_TARGETS)
  get_property(subdirs DIRECTORY ${dir} PROPERTY SUBDIRECTORIES)
  foreach(sub ${subdirs})
    rr_collect_targets(${sub} sub_targets)
    list(APPEND targets ${sub_targets})
  endforeach()
  set(${out} ${targets} PARENT_SCOPE)
endfunction()

# RR_FUZZ_TARGETS: the libraries carry libFuzzer's coverage instrumentation, so the fuzz targets
# (test/CMakeLists.txt, rr_fuzz_replay) link the very objects the tests use. Test programs are left
# uninstrumented: nothing fuzzes them. Without libFuzzer linked in, the coverage callbacks resolve to
# the sanitizer runtime's empty defaults.
if(RR_FUZZ_TARGETS)
  rr_collect_targets(${CMAKE_SOURCE_DIR} _rr_all_targets)
  foreach(t ${_rr_all_targets})
    get_target_property(type ${t} TYPE)
    if(type MATCHES "^(STATIC_LIBRARY|OBJECT_LIBRARY)$" AND NOT t MATCHES "^(rr_test_main|rr_usb_emulator|rr_bench.*)$")
      target_compile_options(${t} PRIVATE -fsanitize=fuzzer-no-link)
    endif()
  endforeach()
endif()

# Precompiled headers. Measured on a 2-vCPU machine, clang -O0 ASan+UBSan: a Beast-heavy server file
# spends ~10 s of ~55 parsing what every such file includes, a Catch2 test file about half its time.
# Unity builds (preset tsan) already share these per batch, so they get none.
if(RR_PCH AND NOT CMAKE_UNITY_BUILD)
  set(_rr_pch_std <algorithm> <atomic> <chrono> <functional> <map> <memory> <mutex> <optional> <string>
      <string_view> <thread> <vector>)
  set(_rr_pch_server <boost/asio/io_context.hpp> <boost/asio/strand.hpp> <boost/asio/steady_timer.hpp>
      <boost/asio/post.hpp> <boost/asio/ip/tcp.hpp> <boost/asio/ssl.hpp> <boost/beast/core.hpp>
      <boost/beast/http.hpp> <boost/beast/websocket.hpp> <nlohmann/json.hpp>)
  # clang stamps a PCH with the headers' times unless told not to; ccache then never reuses it.
  set(_rr_pch_opts $<$<CXX_COMPILER_ID:Clang>:SHELL:-Xclang -fno-pch-timestamp>)
  if(TARGET rr_server)
    target_precompile_headers(rr_server PRIVATE ${_rr_pch_std} ${_rr_pch_server})
    target_compile_options(rr_server PRIVATE ${_rr_pch_opts})
  endif()
  foreach(t rr_core_tests rr_json_tests rr_robdef_tests)
    if(TARGET ${t})
      target_precompile_headers(${t} PRIVATE ${_rr_pch_std} <catch2/catch.hpp>)
      target_compile_options(${t} PRIVATE ${_rr_pch_opts})
    endif()
  endforeach()
  if(TARGET rr_server_tests)
    target_precompile_headers(rr_server_tests PRIVATE ${_rr_pch_std} ${_rr_pch_server} <catch2/catch.hpp>)
    target_compile_options(rr_server_tests PRIVATE ${_rr_pch_opts})
  endif()
endif()
