/* A stand-in for Windows' bcryptprimitives.dll, for wine only: a test fixture, never shipped in
 * an .fmu. Rust's std on Windows imports ProcessPrng from bcryptprimitives.dll, which every
 * Windows 10 and later has and Debian 12's wine 8.0 does not; without it wine's loader refuses
 * the test executables (status c0000135). This one forwards to RtlGenRandom (advapi32's
 * SystemFunction036). `cargo xtask test` builds it with x86_64-w64-mingw32-gcc and puts it
 * beside the cross-built test executables. */
#include <windows.h>

BOOLEAN WINAPI SystemFunction036(PVOID buffer, ULONG length);

__declspec(dllexport) BOOL WINAPI ProcessPrng(PBYTE data, SIZE_T length) {
    return SystemFunction036(data, (ULONG)length);
}
