// A shared library without the entry point: must be refused as "not an orogen plugin".
extern "C" __attribute__((visibility("default"))) int some_other_function(void) { return 42; }
