const int crep_test_shadowed_sub = 3;
