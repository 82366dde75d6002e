function(crep_set_warnings target)
  target_compile_options(${target} PRIVATE -Wall -Wextra -Wpedantic -Wshadow -Wnon-virtual-dtor -Wold-style-cast)
  if(CMAKE_CXX_COMPILER_ID STREQUAL "GNU" AND CMAKE_CXX_COMPILER_VERSION VERSION_GREATER_EQUAL 12
     AND CMAKE_CXX_COMPILER_VERSION VERSION_LESS 13)
    # GCC 12 reports -Wrestrict false positives inside std::string concatenation at -O2/-O3
    # (GCC bug 105329, fixed in GCC 13); they would turn every `"a" + s + "b"` into an error.
    target_compile_options(${target} PRIVATE -Wno-restrict)
  endif()
  if(CREP_SANITIZE AND CMAKE_CXX_COMPILER_ID STREQUAL "GNU")
    # GCC's flow analysis under -fsanitize=address reports -Wmaybe-uninitialized inside libstdc++
    # (std::regex, std::function) that does not occur without the instrumentation.
    target_compile_options(${target} PRIVATE -Wno-maybe-uninitialized)
  endif()
  if(CREP_WERROR)
    target_compile_options(${target} PRIVATE -Werror)
  endif()
endfunction()
