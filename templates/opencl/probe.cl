// The smallest kernel: implc builds it once to find an OpenCL device that can compile.
__kernel void probe(__global float* x) {
    x[0] = 1.0f;
}
