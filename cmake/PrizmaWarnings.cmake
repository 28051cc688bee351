# Warning flags for Prizma's own targets, and the sanitizer trees' run-time defaults in their
# executables: prizma_set_warnings(target).
function(prizma_set_warnings target)
  target_compile_options(${target} PRIVATE -Wall -Wextra -Wpedantic -Wshadow -Wnon-virtual-dtor -Woverloaded-virtual)
  # GCC 12 at -O3 (Release) reports -Wrestrict inside libstdc++'s std::string operator+ where no
  # overlap can happen (GCC bug 105329): off for GCC 12 only.
  if(CMAKE_CXX_COMPILER_ID STREQUAL "GNU" AND CMAKE_CXX_COMPILER_VERSION VERSION_GREATER_EQUAL 12
     AND CMAKE_CXX_COMPILER_VERSION VERSION_LESS 13)
    target_compile_options(${target} PRIVATE -Wno-restrict)
  endif()
  if(PRIZMA_WERROR)
    target_compile_options(${target} PRIVATE -Werror)
  endif()
  # Sanitizer trees: every executable carries the sanitizers' run-time defaults (the file says why).
  get_target_property(type ${target} TYPE)
  if((PRIZMA_SANITIZE OR PRIZMA_FUZZ) AND type STREQUAL "EXECUTABLE")
    target_sources(${target} PRIVATE ${PROJECT_SOURCE_DIR}/cmake/sanitizer_options.cpp)
  endif()
endfunction()

# PRIZMA_FUZZ: libFuzzer coverage instrumentation for every target (the fuzz targets in tests/fuzz/
# add -fsanitize=fuzzer for libFuzzer's main). Needs clang; implies the sanitizers below.
if(PRIZMA_FUZZ)
  if(NOT CMAKE_CXX_COMPILER_ID MATCHES "Clang")
    message(FATAL_ERROR "PRIZMA_FUZZ needs clang (libFuzzer): configure a fresh build folder with "
                        "CC=clang CXX=clang++ cmake -S . -B build-fuzz -DPRIZMA_FUZZ=ON")
  endif()
  add_compile_options(-fsanitize=fuzzer-no-link)
endif()

# PRIZMA_SANITIZE: AddressSanitizer + UndefinedBehaviorSanitizer for everything (gcc or clang).
# UBSan does not recover: the first undefined behaviour aborts the program, so a test fails.
if(PRIZMA_SANITIZE OR PRIZMA_FUZZ)
  add_compile_options(-fsanitize=address,undefined -fno-omit-frame-pointer -fno-sanitize-recover=undefined)
  add_link_options(-fsanitize=address,undefined)
endif()

# prizma_sanitizer_ignorelist(FILE...): the sanitizers skip the third-party header code listed in
# cmake/sanitizer-ignorelist.txt in these sources (clang only; call it in the folder that adds them).
function(prizma_sanitizer_ignorelist)
  if((PRIZMA_SANITIZE OR PRIZMA_FUZZ) AND CMAKE_CXX_COMPILER_ID MATCHES "Clang")
    set_source_files_properties(${ARGN} PROPERTIES COMPILE_OPTIONS
                                "-fsanitize-ignorelist=${PROJECT_SOURCE_DIR}/cmake/sanitizer-ignorelist.txt")
  endif()
endfunction()
