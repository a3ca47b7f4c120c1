// Anchor of the test programs' precompiled header (tests/CMakeLists.txt, iblcheck_test_pch): the
// header is made while this empty file compiles.
