//! Cost of one estimator tick on the host: an IMU, magnetometer, barometer and pitot sample
//! (the 50 Hz loop), and a GPS fix on top (every tenth tick at 5 Hz).

use common::estimator::Estimator;
use common::math::atmosphere::standard_atmosphere;
use common::math::geodetic::GeoPoint;
use common::sensors::{BaroSample, GpsFix, ImuSample, MagSample, PitotSample};
use criterion::{criterion_group, criterion_main, Criterion};
use nalgebra::Vector3;
use std::hint::black_box;

const DT: f32 = 0.02;

fn samples(k: u32) -> (ImuSample, MagSample, BaroSample, PitotSample, GpsFix) {
    // Straight and level north at 17 m/s, with a little roll wobble so nothing is constant.
    let wobble = 0.01 * (k as f32 * 0.1).sin();
    let imu = ImuSample {
        accel: Vector3::new(0.54, -9.79 * wobble, -9.79),
        gyro: Vector3::new(0.01 * (k as f32 * 0.1).cos(), 0.0, 0.0),
    };
    let mag = MagSample {
        field: Vector3::new(0.18, 0.52 * wobble, 0.52),
    };
    let air = standard_atmosphere(100.0_f32);
    let baro = BaroSample {
        pressure_pa: air.pressure_pa,
        temperature_c: air.temperature_k - 273.15,
    };
    let pitot = PitotSample {
        diff_pressure_pa: 0.5 * air.density * 17.0 * 17.0,
    };
    let north_e7 = (17.0 * DT * k as f32 / 0.0111) as i32;
    let gps = GpsFix {
        position: GeoPoint {
            lat_e7: 447_258_357 + north_e7,
            lon_e7: -930_750_132,
        },
        alt_amsl_m: 100.0,
        vel_ned: Vector3::new(17.0, 0.0, 0.0),
        fix_type: 3,
        satellites: 10,
        hdop: 0.8,
    };
    (imu, mag, baro, pitot, gps)
}

fn converged() -> (Estimator, u32) {
    let mut e = Estimator::default();
    let mut k = 0;
    while k < 1500 {
        let (imu, mag, baro, pitot, gps) = samples(k);
        e.update_imu(&imu, DT);
        e.update_mag(&mag);
        e.update_baro(&baro);
        e.update_pitot(&pitot);
        if k % 10 == 0 {
            e.update_gps(&gps);
        }
        k += 1;
    }
    (e, k)
}

fn bench(c: &mut Criterion) {
    let (mut e, k0) = converged();
    let (imu, mag, baro, pitot, gps) = samples(k0);
    c.bench_function("estimator 50 Hz tick (imu+mag+baro+pitot)", |b| {
        b.iter(|| {
            e.update_imu(black_box(&imu), DT);
            e.update_mag(black_box(&mag));
            e.update_baro(black_box(&baro));
            e.update_pitot(black_box(&pitot));
        })
    });
    let (mut e, _) = converged();
    c.bench_function("estimator gps fix", |b| {
        b.iter(|| e.update_gps(black_box(&gps)))
    });
    let (e, _) = converged();
    c.bench_function("estimator state()", |b| b.iter(|| black_box(&e).state()));
}

criterion_group!(benches, bench);
criterion_main!(benches);
