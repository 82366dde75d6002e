const int crep_test_shadowed_root = 4;
