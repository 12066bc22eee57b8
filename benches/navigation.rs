//! Throughput of the strapdown navigator, the simulator and the IMU text reader, in samples or
//! bytes per second (criterion reports them as throughput). Run: `cargo bench --bench navigation`.

use criterion::{black_box, criterion_group, criterion_main, Criterion, Throughput};
use sinsmodel::nav::strapdown::{Navigator, Vertical};
use sinsmodel::sim::scenario::Scenario;
use sinsmodel::sim::simulator::simulate;

fn scenario(rate: f64, secs: f64, vib: bool) -> Scenario {
    let v = if vib {
        "[[vibration]]\nkind = \"sine\"\naxis = \"n\"\namplitude = \"6 g\"\nfreq_hz = 90.0\n\
         [[vibration]]\nkind = \"sine\"\naxis = \"e\"\namplitude = \"6 g\"\nfreq_hz = 90.0\n\
         [[vibration]]\nkind = \"sine\"\naxis = \"d\"\namplitude = \"6 g\"\nfreq_hz = 90.0\n"
    } else {
        ""
    };
    Scenario::parse(
        &format!(
            "name = \"b\"\nimu_rate_hz = {rate}\n[start]\nlat_deg = 28.22\nlon_deg = 112.99\n[[segment]]\nkind = \"rest\"\n\
             duration_s = {secs}\n{v}[errors]\neps_x = \"0.01 deg/h\"\nd_x = \"5e-5 s^2/m\"\n[noise]\narw = \"0.01 deg/sqrt(h)\"\n"
        ),
        "bench",
    )
    .unwrap()
}

fn bench(c: &mut Criterion) {
    let sc = scenario(2000.0, 50.0, true);
    let sim = simulate(&sc, |_| {});
    let n = sim.imu.samples.len() as u64;

    let mut g = c.benchmark_group("navigator");
    g.throughput(Throughput::Elements(n));
    g.sample_size(20);
    g.bench_function("strapdown_2kHz_vibration", |b| {
        b.iter(|| {
            let mut nav = Navigator::new(sim.start, Vertical::Fixed);
            for s in &sim.imu.samples {
                nav.step(&s.dtheta, &s.dv, 5e-4);
            }
            black_box(nav.state.lat)
        })
    });
    g.finish();

    let mut g = c.benchmark_group("simulator");
    g.throughput(Throughput::Elements(n));
    g.sample_size(10);
    g.bench_function("sine_vibration_3axis_2kHz", |b| {
        b.iter(|| black_box(simulate(&sc, |_| {}).imu.samples.len()))
    });
    let rest = scenario(100.0, 1000.0, false);
    g.throughput(Throughput::Elements(100_000));
    g.bench_function("rest_100Hz", |b| {
        b.iter(|| black_box(simulate(&rest, |_| {}).imu.samples.len()))
    });
    g.finish();

    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("imu.txt");
    sinsmodel::io::imu::write_text(&path, &sim.imu, "bench").unwrap();
    let bytes = std::fs::metadata(&path).unwrap().len();
    let mut g = c.benchmark_group("imu_text");
    g.throughput(Throughput::Bytes(bytes));
    g.sample_size(10);
    g.bench_function("read", |b| {
        b.iter(|| {
            black_box(
                sinsmodel::io::imu_stream::read_text(&path)
                    .unwrap()
                    .samples
                    .len(),
            )
        })
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
