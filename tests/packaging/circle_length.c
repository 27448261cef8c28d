/* circle_length.c - a program built against the installed libkmorph: the
 * quarter circle of radius 2 as a rational quadratic (weights 1, sqrt(2)/2,
 * 1) must have length pi and every point at distance 2 from the centre.
 * Prints the header's and the library's versions, then "ok" or why not. */
#include <km/kmorph.h>
#include <math.h>
#include <stdio.h>

static const double PI = 3.14159265358979323846;

int main(void) {
  const double knots[] = {0, 0, 0, 1, 1, 1};
  const double cp[] = {2, 0, 2, 2, 0, 2};
  const double w[] = {1, sqrt(0.5), 1};
  km_curve c;
  km_curve_init(&c);
  km_error err;
  if (km_curve_create(&c, 2, 3, knots, cp, w, false, &err) != KM_OK) {
    printf("km_curve_create: %s\n", err.message);
    return 1;
  }
  printf("header %s library %s\n", KM_VERSION_STRING, km_version());
  double length = km_curve_length(&c);
  double worst = 0;
  for (int i = 0; i <= 16; i++) {
    double p[1][2];
    km_curve_eval(&c, i / 16.0, 0, p);
    double off = fabs(hypot(p[0][0], p[0][1]) - 2);
    worst = off > worst ? off : worst;
  }
  km_curve_free(&c);
  if (fabs(length - PI) > 1e-6 || worst > 1e-12) {
    printf("length %.12g (pi %.12g), radius off by %.3g\n", length, PI, worst);
    return 1;
  }
  printf("ok\n");
  return 0;
}
