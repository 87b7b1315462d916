#define_import_path illum::constants

const PI: f32 = 3.14159265358979323846;
const TWO_PI: f32 = 6.28318530717958647692;
const INV_PI: f32 = 0.31830988618379067154;
