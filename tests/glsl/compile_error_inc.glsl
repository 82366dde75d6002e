// Test fixture: the error below is deliberate (line 4).

float crep_test_broken() {
  return crep_test_undefined_symbol;
}
