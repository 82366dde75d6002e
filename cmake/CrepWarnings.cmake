function(crep_set_warnings target)
  target_compile_options(${target} PRIVATE -Wall -Wextra -Wpedantic -Wshadow -Wconversion-null
                                           -Wnon-virtual-dtor -Wold-style-cast)
  if(CREP_WERROR)
    target_compile_options(${target} PRIVATE -Werror)
  endif()
endfunction()
