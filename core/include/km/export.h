/* export.h - which symbols of libkmorph a program may link against.
 *
 * The core is compiled with -fvisibility=hidden, so only declarations
 * marked KM_API - the public functions of the km/ headers - are exported
 * from libkmorph.so; the internal km__ helpers and every other function
 * stay inside the library, where the linker binds them directly and they
 * can change without touching the ABI. A static link sees no difference.
 */
#ifndef KM_EXPORT_H
#define KM_EXPORT_H

#if defined(__GNUC__) || defined(__clang__)
#define KM_API __attribute__((visibility("default")))
#else
#define KM_API
#endif

#endif
