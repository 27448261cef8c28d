/* kmorph.h - umbrella header of libkmorph. */
#ifndef KM_KMORPH_H
#define KM_KMORPH_H
#include "km/curve.h"
#include "km/fn.h"
#include "km/limits.h"
#include "km/morph.h"
#include "km/reconstruct.h"
#include "km/signature.h"
#include "km/status.h"
#endif
