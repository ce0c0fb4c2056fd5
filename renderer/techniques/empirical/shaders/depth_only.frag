#version 450 core
// Front layer (Sec. 3.1, step 1): only the depth attachment is written.
void main() {}
