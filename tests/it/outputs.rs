//! 3D and growth outputs: OBJ with its material library, binary glTF (read
//! back with the `gltf` crate and checked by the Khronos validator), the
//! `--view` camera, growth frames and the animated PNG.

use crate::support::{lsy_files, read_text, rel, root};
use lsyc::render::{self, obj::material_name};
use lsyc::run::{self, Derived, Format, Options, Picture};
use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn lsyc(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_lsyc"))
        .args(args)
        .env("NO_COLOR", "1")
        .output()
        .expect("the lsyc binary runs")
}

/// Runs lsyc and demands success.
fn lsyc_ok(args: &[&str]) {
    let out = lsyc(args);
    assert!(
        out.status.success(),
        "lsyc {args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
}

fn example(name: &str) -> PathBuf {
    root().join("lang-examples").join(name)
}

fn s(p: &Path) -> &str {
    p.to_str().expect("utf-8 path")
}

fn derive_file(path: &Path, steps: Option<u32>) -> Derived {
    let text = read_text(path);
    let fe = lsyc::frontend::run(&text, Vec::new(), &[]);
    let checked = fe.checked.as_ref().expect("the program checks");
    let opts = Options {
        steps,
        ..Options::default()
    };
    run::derive(&fe.file, checked, &opts, &|_, _| {})
        .unwrap_or_else(|d| panic!("{}: {}", rel(path), d.message))
}

fn output(d: &Derived, format: Format, picture: &Picture) -> (Vec<u8>, run::Written) {
    let mut out = Vec::new();
    match run::write_output_full(d, format, picture, 0, &mut out) {
        Ok(w) => (out, w),
        Err(run::OutputError::Diagnostic(d)) => panic!("{}", d.message),
        Err(run::OutputError::Io(e)) => panic!("{e}"),
    }
}

fn has_scene(path: &Path) -> bool {
    let text = read_text(path);
    let fe = lsyc::frontend::run(&text, Vec::new(), &[]);
    fe.file
        .items
        .stmts
        .iter()
        .any(|i| matches!(i.node, lsyc::ast::Item::Scene(_)))
}

/// The gallery programs whose first lsystem draws in 3D (turns `&` `^` `\`
/// `/` `|` or tubes), scenes aside.
fn gallery_3d() -> Vec<PathBuf> {
    let found: Vec<PathBuf> = lsy_files(&["lang-examples"])
        .into_iter()
        .filter(|p| !has_scene(p) && derive_file(p, Some(0)).prog.is_3d)
        .collect();
    assert!(found.len() >= 3, "3D gallery programs: {found:?}");
    eprintln!(
        "3D gallery: {:?}",
        found.iter().map(|p| rel(p)).collect::<Vec<_>>()
    );
    found
}

/// An OBJ file as the tests need it: positions, and per (object, material)
/// the distinct (vertex, normal) corners and the triangle count.
#[derive(Default)]
struct ObjMesh {
    v: Vec<[f64; 3]>,
    corners: BTreeMap<(String, String), BTreeSet<(usize, usize)>>,
    triangles: BTreeMap<(String, String), usize>,
    mtllib: Option<String>,
}

fn parse_obj(text: &str) -> ObjMesh {
    let mut m = ObjMesh::default();
    let (mut object, mut material) = (String::new(), String::new());
    for line in text.lines() {
        let mut it = line.split_whitespace();
        match it.next() {
            Some("v") => {
                let xs: Vec<f64> = it.map(|x| x.parse().expect("number")).collect();
                m.v.push([xs[0], xs[1], xs[2]]);
            }
            Some("o") => object = it.next().unwrap_or("").to_string(),
            Some("usemtl") => material = it.next().unwrap_or("").to_string(),
            Some("mtllib") => m.mtllib = it.next().map(str::to_string),
            Some("f") => {
                let key = (object.clone(), material.clone());
                let corners: Vec<(usize, usize)> = it
                    .map(|c| {
                        let (v, n) = c.split_once("//").expect("v//vn");
                        (v.parse().expect("index"), n.parse().expect("index"))
                    })
                    .collect();
                *m.triangles.entry(key.clone()).or_default() += corners.len() - 2;
                m.corners.entry(key).or_default().extend(corners);
            }
            _ => {}
        }
    }
    m
}

#[test]
fn obj_writes_its_material_library_beside_it() {
    let dir = tempfile::tempdir().expect("tempdir");
    let obj = dir.path().join("bush.obj");
    lsyc_ok(&["run", s(&example("bush-3d.lsy")), "-n", "3", "-o", s(&obj)]);
    let text = std::fs::read_to_string(&obj).expect("the OBJ");
    assert_eq!(parse_obj(&text).mtllib.as_deref(), Some("bush.mtl"));
    let (models, materials) =
        tobj::load_obj(&obj, &tobj::LoadOptions::default()).expect("tobj reads the OBJ");
    let materials = materials.expect("tobj reads the MTL named by mtllib");
    let used: BTreeSet<String> = text
        .lines()
        .filter_map(|l| l.strip_prefix("usemtl "))
        .map(str::to_string)
        .collect();
    let named: BTreeSet<String> = materials.iter().map(|m| m.name.clone()).collect();
    assert_eq!(
        used, named,
        "one material per colour used, named as usemtl names it"
    );
    for m in &materials {
        let c: u32 = m
            .name
            .strip_prefix("lsyc_color")
            .expect("prefix")
            .parse()
            .expect("index");
        let kd = m.diffuse.expect("Kd");
        let want = render::palette_linear(c);
        for k in 0..3 {
            assert!(
                (f64::from(kd[k]) - want[k]).abs() < 1e-6,
                "{}: {kd:?}",
                m.name
            );
        }
    }
    assert!(!models.is_empty());
    for model in &models {
        assert!(
            model.mesh.material_id.is_some(),
            "{} has a material",
            model.name
        );
    }
}

#[test]
fn obj_frames_each_get_their_own_material_library() {
    let dir = tempfile::tempdir().expect("tempdir");
    let obj = dir.path().join("h.obj");
    lsyc_ok(&[
        "run",
        s(&example("helix.lsy")),
        "-n",
        "1",
        "--frames",
        "-o",
        s(&obj),
    ]);
    for k in ["000", "001"] {
        let text = std::fs::read_to_string(dir.path().join(format!("h-{k}.obj"))).expect("frame");
        assert_eq!(parse_obj(&text).mtllib, Some(format!("h-{k}.mtl")));
        assert!(dir.path().join(format!("h-{k}.mtl")).exists());
    }
}

/// A primitive read back: POSITION count, triangle count, accessor min and max.
type PrimitiveSummary = (usize, usize, [f32; 3], [f32; 3]);

/// The GLB read back with the `gltf` crate.
struct Glb {
    nodes: Vec<String>,
    /// Per (node, material): POSITION count, triangle count, bounds.
    primitives: BTreeMap<(String, String), PrimitiveSummary>,
    colors: BTreeMap<String, [f32; 4]>,
}

fn read_glb(bytes: &[u8]) -> Glb {
    let g = gltf::Gltf::from_slice(bytes).expect("the gltf crate reads the GLB");
    let blob = g.blob.clone();
    let scene = g.default_scene().expect("a default scene");
    let mut out = Glb {
        nodes: Vec::new(),
        primitives: BTreeMap::new(),
        colors: BTreeMap::new(),
    };
    for node in scene.nodes() {
        let name = node.name().unwrap_or("").to_string();
        out.nodes.push(name.clone());
        let Some(mesh) = node.mesh() else { continue };
        for p in mesh.primitives() {
            let material = p.material().name().unwrap_or("").to_string();
            out.colors.insert(
                material.clone(),
                p.material().pbr_metallic_roughness().base_color_factor(),
            );
            let reader = p.reader(|_| blob.as_deref());
            let positions: Vec<[f32; 3]> = reader.read_positions().expect("positions").collect();
            let normals: Vec<[f32; 3]> = reader.read_normals().expect("normals").collect();
            assert_eq!(positions.len(), normals.len());
            let indices: Vec<u32> = reader.read_indices().expect("indices").into_u32().collect();
            assert!(indices.iter().all(|&i| (i as usize) < positions.len()));
            let b = p.bounding_box();
            out.primitives.insert(
                (name.clone(), material),
                (positions.len(), indices.len() / 3, b.min, b.max),
            );
        }
    }
    out
}

/// GLB and OBJ of one drawing hold the same mesh: the same corners and
/// triangles per object and colour, the same bounds, the same colours.
fn same_mesh(obj: &ObjMesh, glb: &Glb) {
    assert_eq!(
        obj.corners.keys().collect::<Vec<_>>(),
        glb.primitives.keys().collect::<Vec<_>>()
    );
    let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
    for (key, corners) in &obj.corners {
        let (count, triangles, min, max) = glb.primitives[key];
        assert_eq!(count, corners.len(), "{key:?}: vertices");
        assert_eq!(triangles, obj.triangles[key], "{key:?}: triangles");
        for &(v, _) in corners {
            for k in 0..3 {
                lo[k] = lo[k].min(obj.v[v - 1][k]);
                hi[k] = hi[k].max(obj.v[v - 1][k]);
                let x = obj.v[v - 1][k];
                assert!(
                    f64::from(min[k]) <= x + 1e-6 * x.abs().max(1.0),
                    "{key:?}: min"
                );
                assert!(
                    f64::from(max[k]) >= x - 1e-6 * x.abs().max(1.0),
                    "{key:?}: max"
                );
            }
        }
    }
    let (mut glo, mut ghi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
    for &(_, _, min, max) in glb.primitives.values() {
        for k in 0..3 {
            glo[k] = glo[k].min(f64::from(min[k]));
            ghi[k] = ghi[k].max(f64::from(max[k]));
        }
    }
    let scale = hi
        .iter()
        .chain(lo.iter())
        .fold(1e-9f64, |m, x| m.max(x.abs()));
    for k in 0..3 {
        // OBJ prints 7 significant digits; glTF holds 32-bit floats.
        assert!(
            (glo[k] - lo[k]).abs() <= 2e-6 * scale,
            "min {glo:?} vs {lo:?}"
        );
        assert!(
            (ghi[k] - hi[k]).abs() <= 2e-6 * scale,
            "max {ghi:?} vs {hi:?}"
        );
    }
    for (name, rgba) in &glb.colors {
        let c: u32 = name
            .strip_prefix("lsyc_color")
            .expect("prefix")
            .parse()
            .expect("index");
        assert_eq!(name, &material_name(c));
        let want = render::palette_linear(c);
        for k in 0..3 {
            assert!(
                (f64::from(rgba[k]) - want[k]).abs() < 1e-6,
                "{name}: {rgba:?}"
            );
        }
        assert_eq!(rgba[3], 1.0);
    }
}

#[test]
fn glb_reads_back_as_the_obj_mesh() {
    for (file, steps) in [
        ("bush-3d.lsy", 4),
        ("hilbert-3d.lsy", 2),
        ("plant-d.lsy", 3),
    ] {
        let d = derive_file(&example(file), Some(steps));
        let (obj, wo) = output(&d, Format::Obj, &Picture::default());
        let (glb, wg) = output(&d, Format::Glb, &Picture::default());
        assert_eq!(wo.materials, wg.materials, "{file}");
        let obj = parse_obj(&String::from_utf8(obj).expect("utf-8"));
        let glb = read_glb(&glb);
        assert_eq!(
            glb.nodes,
            vec![d.prog.name.clone()],
            "{file}: one node, the lsystem"
        );
        same_mesh(&obj, &glb);
    }
}

#[test]
fn scene_glb_has_one_node_per_guide() {
    let path = example("tree.lsy");
    let text = read_text(&path);
    let fe = lsyc::frontend::run(&text, Vec::new(), &[]);
    let checked = fe.checked.as_ref().expect("checks");
    let opts = Options {
        steps: Some(30),
        ..Options::default()
    };
    let r = run::run_scene(&fe.file, checked, None, &opts).expect("scene runs");
    let mut glb = Vec::new();
    let mut obj = Vec::new();
    let ok = |r: Result<run::SceneStats, run::OutputError>| assert!(r.is_ok());
    ok(run::write_scene(
        &r,
        Some(Format::Glb),
        Picture::default(),
        0,
        false,
        &mut glb,
    ));
    ok(run::write_scene(
        &r,
        Some(Format::Obj),
        Picture::default(),
        0,
        false,
        &mut obj,
    ));
    let glb = read_glb(&glb);
    let guides: Vec<String> = r.scene.guides.iter().map(|g| g.name.clone()).collect();
    assert_eq!(glb.nodes, guides);
    assert!(glb.primitives.len() >= 2, "the guides grew geometry");
    same_mesh(&parse_obj(&String::from_utf8(obj).expect("utf-8")), &glb);
}

/// Installs the pinned validator (`npm ci`) when it is missing.
fn validator_dir() -> PathBuf {
    let dir = root().join("tests/gltf");
    if !dir.join("node_modules/gltf-validator").exists() {
        let status = Command::new("npm")
            .args(["ci", "--no-audit", "--no-fund"])
            .current_dir(&dir)
            .status()
            .unwrap_or_else(|e| {
                panic!("the glTF validator needs Node.js and npm (`npm ci` in tests/gltf): {e}")
            });
        assert!(status.success(), "`npm ci` in tests/gltf failed: {status}");
    }
    dir
}

#[test]
fn khronos_validator_accepts_the_3d_gallery_and_a_scene() {
    let dir = tempfile::tempdir().expect("tempdir");
    let mut files = Vec::new();
    for p in gallery_3d() {
        let stem = p.file_stem().and_then(|s| s.to_str()).expect("name");
        let out = dir.path().join(format!("{stem}.glb"));
        lsyc_ok(&["run", s(&p), "-o", s(&out)]);
        files.push(out);
    }
    for scene in ["tree.lsy", "palm.lsy"] {
        let out = dir.path().join(scene.replace(".lsy", "-scene.glb"));
        lsyc_ok(&["run", s(&example(scene)), "-o", s(&out)]);
        files.push(out);
    }
    let node = Command::new("node")
        .arg(validator_dir().join("validate.js"))
        .args(&files)
        .output()
        .unwrap_or_else(|e| panic!("the glTF validator needs Node.js (`node`): {e}"));
    assert!(
        node.status.success(),
        "{}",
        String::from_utf8_lossy(&node.stderr)
    );
    let text = String::from_utf8(node.stdout).expect("utf-8");
    let reports: Vec<serde_json::Value> = text
        .lines()
        .map(|l| serde_json::from_str(l).expect("one JSON report per line"))
        .collect();
    assert_eq!(reports.len(), files.len(), "{text}");
    for r in &reports {
        assert!(r.get("failure").is_none(), "{r}");
        assert_eq!(r["errors"], 0, "validator errors: {r}");
        // No warnings either (docs/outputs.md lists the ones that would be
        // acceptable; there are none today).
        assert_eq!(r["warnings"], 0, "validator warnings: {r}");
    }
}

fn png_size(bytes: &[u8]) -> (u32, u32) {
    let decoder = png::Decoder::new(std::io::Cursor::new(bytes));
    let reader = decoder.read_info().expect("a PNG");
    let info = reader.info();
    (info.width, info.height)
}

#[test]
fn view_turns_the_camera_and_defaults_to_30_20() {
    let dir = tempfile::tempdir().expect("tempdir");
    let bush = example("bush-3d.lsy");
    let run = |name: &str, view: Option<&str>| {
        let out = dir.path().join(name);
        let mut args = vec!["run", s(&bush), "-n", "3", "--size", "256", "-o", s(&out)];
        if let Some(v) = view {
            args.extend(["--view", v]);
        }
        lsyc_ok(&args);
        std::fs::read(&out).expect("output")
    };
    for ext in ["svg", "png"] {
        let default = run(&format!("default.{ext}"), None);
        let same = run(&format!("same.{ext}"), Some("30,20"));
        let side = run(&format!("side.{ext}"), Some("120,5"));
        let top = run(&format!("top.{ext}"), Some("-45,-60"));
        assert_eq!(default, same, "{ext}: the default view is --view 30,20");
        assert_ne!(default, side, "{ext}: another view draws another picture");
        assert_ne!(side, top, "{ext}");
    }
    // A 2D program ignores the camera.
    let koch = example("koch-island.lsy");
    let a = dir.path().join("a.svg");
    let b = dir.path().join("b.svg");
    lsyc_ok(&["run", s(&koch), "-n", "1", "-o", s(&a)]);
    lsyc_ok(&["run", s(&koch), "-n", "1", "-o", s(&b), "--view", "80,40"]);
    assert_eq!(std::fs::read(a).ok(), std::fs::read(b).ok());
}

#[test]
fn bad_views_are_usage_errors() {
    let out = tempfile::tempdir().expect("tempdir");
    let png = out.path().join("x.png");
    for (view, says) in [
        ("30", "AZIMUTH,ELEVATION"),
        ("30,20,10", "AZIMUTH,ELEVATION"),
        ("a,20", "azimuth `a`"),
        ("30,inf", "elevation `inf`"),
        ("30,91", "beyond ±90"),
        ("", "AZIMUTH,ELEVATION"),
    ] {
        let r = lsyc(&[
            "run",
            s(&example("bush-3d.lsy")),
            "--view",
            view,
            "-o",
            s(&png),
        ]);
        assert_eq!(r.status.code(), Some(2), "--view {view:?}");
        let err = String::from_utf8_lossy(&r.stderr);
        assert!(err.contains(says), "--view {view:?}: {err}");
        assert!(!png.exists());
    }
}

/// `--frames` writes steps + 1 files in one view box, and frame k is `-n k`
/// drawn in the final step's view box.
#[test]
fn frames_are_each_step_in_the_final_view_box() {
    for (file, steps, view) in [
        ("plant-a.lsy", 3, None),
        ("bush-3d.lsy", 3, Some([60.0, 10.0])),
    ] {
        let dir = tempfile::tempdir().expect("tempdir");
        let path = example(file);
        let n = steps.to_string();
        let view_arg = view.map(|[a, e]: [f64; 2]| format!("{a},{e}"));
        let mut sizes = BTreeSet::new();
        let mut boxes = BTreeSet::new();
        for ext in ["png", "svg"] {
            let out = dir.path().join(format!("g.{ext}"));
            let mut args = vec![
                "run",
                s(&path),
                "-n",
                &n,
                "--size",
                "200",
                "--frames",
                "-o",
                s(&out),
            ];
            if let Some(v) = &view_arg {
                args.extend(["--view", v]);
            }
            lsyc_ok(&args);
            let mut names: Vec<String> = std::fs::read_dir(dir.path())
                .expect("dir")
                .flatten()
                .map(|e| e.file_name().to_string_lossy().into_owned())
                .filter(|f| f.ends_with(ext))
                .collect();
            names.sort();
            let want: Vec<String> = (0..=steps).map(|k| format!("g-{k:03}.{ext}")).collect();
            assert_eq!(names, want, "{file}: step count + 1 files");
            let last = derive_file(&path, Some(steps));
            let picture = Picture {
                size: 200,
                view,
                ..Picture::default()
            };
            let v = picture.view(last.prog.is_3d);
            let (_, bounds) = run::measure_in(&last, 0, v).expect("measures");
            let framed = Picture {
                bounds: Some(bounds),
                ..picture
            };
            let format = Format::from_path(Path::new(&names[0])).expect("format");
            for (k, name) in names.iter().enumerate() {
                let bytes = std::fs::read(dir.path().join(name)).expect("frame");
                let d = derive_file(&path, Some(k as u32));
                let (want, _) = output(&d, format, &framed);
                assert!(
                    bytes == want,
                    "{file}: {name} is not -n {k} in the final view box"
                );
                if ext == "png" {
                    sizes.insert(png_size(&bytes));
                } else {
                    let text = String::from_utf8(bytes).expect("utf-8");
                    let vb = text
                        .split("viewBox=\"")
                        .nth(1)
                        .and_then(|t| t.split('"').next());
                    boxes.insert(vb.expect("a viewBox").to_string());
                }
            }
        }
        assert_eq!(sizes.len(), 1, "{file}: one pixel size: {sizes:?}");
        assert_eq!(boxes.len(), 1, "{file}: one view box: {boxes:?}");
    }
}

#[test]
fn animated_png_has_one_frame_per_step() {
    let dir = tempfile::tempdir().expect("tempdir");
    let out = dir.path().join("grow.apng");
    lsyc_ok(&[
        "run",
        s(&example("plant-a.lsy")),
        "-n",
        "4",
        "--size",
        "160",
        "-o",
        s(&out),
    ]);
    let bytes = std::fs::read(&out).expect("apng");
    let decoder = png::Decoder::new(std::io::Cursor::new(&bytes[..]));
    let mut reader = decoder.read_info().expect("a PNG");
    let actl = reader.info().animation_control().expect("an animated PNG");
    assert_eq!(actl.num_frames, 5);
    assert_eq!(actl.num_plays, 0, "plays forever");
    // Every frame decodes, and the last one is `-n 4` as a still PNG.
    let mut buf = vec![0; reader.output_buffer_size().expect("size")];
    let mut last = Vec::new();
    for _ in 0..5 {
        let info = reader.next_frame(&mut buf).expect("a frame");
        last = buf[..info.buffer_size()].to_vec();
    }
    let still = dir.path().join("still.png");
    lsyc_ok(&[
        "run",
        s(&example("plant-a.lsy")),
        "-n",
        "4",
        "--size",
        "160",
        "-o",
        s(&still),
    ]);
    let still = std::fs::read(&still).expect("png");
    let mut r = png::Decoder::new(std::io::Cursor::new(&still[..]))
        .read_info()
        .expect("png");
    let mut pixels = vec![0; r.output_buffer_size().expect("size")];
    let info = r.next_frame(&mut pixels).expect("frame");
    assert_eq!(last, pixels[..info.buffer_size()].to_vec());
}

#[test]
fn frames_and_animations_of_scenes_are_usage_errors() {
    let dir = tempfile::tempdir().expect("tempdir");
    let tree = example("tree.lsy");
    for out in ["t.png", "t.apng"] {
        let out = dir.path().join(out);
        let mut args = vec!["run", s(&tree), "-o", s(&out)];
        if out.extension().is_some_and(|e| e == "png") {
            args.push("--frames");
        }
        let r = lsyc(&args);
        assert_eq!(r.status.code(), Some(2), "{args:?}");
        assert!(String::from_utf8_lossy(&r.stderr).contains("not yet for a scene"));
    }
}

#[test]
fn glb_beyond_the_memory_limit_is_a_clear_error() {
    let dir = tempfile::tempdir().expect("tempdir");
    let out = dir.path().join("bush.glb");
    let r = lsyc(&[
        "run",
        s(&example("bush-3d.lsy")),
        "-n",
        "5",
        "--max-memory",
        "1",
        "-o",
        s(&out),
    ]);
    assert_eq!(r.status.code(), Some(1));
    let err = String::from_utf8_lossy(&r.stderr);
    assert!(err.contains("--max-memory"), "{err}");
    assert!(!out.exists(), "nothing is written");
}

/// Stepping from the axiom gives each step's string exactly as `-n k` does,
/// random draws included, and leaves the final string in place.
#[test]
fn each_step_replays_stochastic_growth() {
    let path = example("stochastic-plant.lsy");
    let mut last = derive_file(&path, Some(5));
    let final_string = format!("{:?}", txt_of(&last));
    let mut seen = Vec::new();
    let r = run::each_step(&mut last, &Picture::default(), 0, &mut |d, framed| {
        assert!(framed.bounds.is_some(), "frames share a view box");
        seen.push((d.steps, txt_of(d)));
        Ok(())
    });
    assert!(r.is_ok());
    assert_eq!(seen.len(), 6);
    for (k, text) in &seen {
        assert_eq!(text, &txt_of(&derive_file(&path, Some(*k))), "step {k}");
    }
    assert_eq!(format!("{:?}", txt_of(&last)), final_string);
}

fn txt_of(d: &Derived) -> String {
    let (bytes, _) = output(d, Format::Txt, &Picture::default());
    String::from_utf8(bytes).expect("utf-8")
}

#[test]
fn outputs_through_a_pipe_or_a_link_keep_them_in_place() {
    use std::os::unix::fs::FileTypeExt;
    let dir = tempfile::tempdir().expect("tempdir");
    let program = example("koch-island.lsy");

    // A named pipe (as `/dev/null` or `/dev/stdout` are devices): written
    // through, never replaced by a plain file.
    let pipe = dir.path().join("pipe.svg");
    let made = Command::new("mkfifo")
        .arg(&pipe)
        .status()
        .expect("mkfifo runs");
    assert!(made.success());
    let reader = {
        let pipe = pipe.clone();
        std::thread::spawn(move || std::fs::read(&pipe).expect("read the pipe"))
    };
    lsyc_ok(&["run", s(&program), "-o", s(&pipe)]);
    let through = reader.join().expect("reader");
    assert!(String::from_utf8_lossy(&through).contains("<svg"));
    let kind = std::fs::symlink_metadata(&pipe).expect("pipe").file_type();
    assert!(kind.is_fifo(), "the pipe is still a pipe: {kind:?}");

    // A symbolic link: it stays a link, and its target gets the drawing.
    let target = dir.path().join("drawing.svg");
    std::fs::write(&target, "old").expect("write target");
    let link = dir.path().join("link.svg");
    std::os::unix::fs::symlink(&target, &link).expect("symlink");
    lsyc_ok(&["run", s(&program), "-o", s(&link)]);
    let kind = std::fs::symlink_metadata(&link).expect("link").file_type();
    assert!(kind.is_symlink(), "the link is still a link");
    assert_eq!(
        std::fs::read(&target).expect("target"),
        through,
        "the link's target holds the same drawing as went through the pipe"
    );
    let names: BTreeSet<_> = std::fs::read_dir(dir.path())
        .expect("list")
        .map(|e| e.expect("entry").file_name())
        .collect();
    assert_eq!(names.len(), 3, "no temporary file left behind: {names:?}");
}
