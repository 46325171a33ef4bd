//! `--bcf FILE.bcfzip` through the real binary: the archive is read back with the zip crate and
//! every XML file parsed with roxmltree; topic GUIDs are deterministic and follow the stable
//! finding ids; components, colours, camera (metres, Z up) and lines are checked.

use assert_cmd::Command;
use meshclash::report::Report;
use std::collections::BTreeMap;
use std::io::Read;
use std::path::{Path, PathBuf};

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn shipped(name: &str) -> String {
    root().join("meshes").join(name).display().to_string()
}

/// Run with `--bcf` (and `-o`); every file of the archive, and the report.
fn run(dir: &Path, args: &[&str]) -> (BTreeMap<String, String>, Report, Vec<u8>) {
    let bcf = dir.join("r.bcfzip");
    let json = dir.join("r.json");
    let out = Command::cargo_bin("meshclash")
        .unwrap()
        .args(args)
        .args(["-q", "--no-timings", "--bcf"])
        .arg(&bcf)
        .arg("-o")
        .arg(&json)
        .output()
        .unwrap();
    assert!(out.status.code().unwrap() < 2, "{}", String::from_utf8_lossy(&out.stderr));
    let bytes = std::fs::read(&bcf).unwrap();
    let mut z = zip::ZipArchive::new(std::io::Cursor::new(bytes.clone())).unwrap();
    let mut files = BTreeMap::new();
    for i in 0..z.len() {
        let mut f = z.by_index(i).unwrap();
        let name = f.name().unwrap().to_string();
        let mut s = String::new();
        f.read_to_string(&mut s).unwrap();
        // Every file is well-formed XML.
        roxmltree::Document::parse(&s).unwrap_or_else(|e| panic!("{name}: {e}"));
        files.insert(name, s);
    }
    let rep: Report = serde_json::from_slice(&std::fs::read(&json).unwrap()).unwrap();
    (files, rep, bytes)
}

fn topics(files: &BTreeMap<String, String>) -> Vec<String> {
    files.keys().filter_map(|k| k.strip_suffix("/markup.bcf")).map(str::to_string).collect()
}

fn text<'a>(doc: &'a roxmltree::Document, tag: &str) -> Vec<&'a str> {
    doc.descendants().filter(|n| n.has_tag_name(tag)).map(|n| n.text().unwrap_or("")).collect()
}

fn xyz(doc: &roxmltree::Document, tag: &str) -> [f64; 3] {
    let n = doc.descendants().find(|n| n.has_tag_name(tag)).unwrap();
    let c =
        |k: &str| n.children().find(|c| c.has_tag_name(k)).unwrap().text().unwrap().parse::<f64>().unwrap();
    [c("X"), c("Y"), c("Z")]
}

#[test]
fn scene_regions_become_topics_with_parts_camera_and_lines() {
    let d = tempfile::tempdir().unwrap();
    let (files, rep, bytes) = run(d.path(), &["scene", &shipped("pins.glb")]);
    let version = roxmltree::Document::parse(&files["bcf.version"]).unwrap();
    assert_eq!(version.root_element().attribute("VersionId"), Some("2.1"));
    let guids = topics(&files);
    assert_eq!(guids.len(), rep.regions.len());
    assert_eq!(guids.len(), 6);
    assert_eq!(files.len(), 1 + 2 * guids.len());
    for g in &guids {
        let markup = roxmltree::Document::parse(&files[&format!("{g}/markup.bcf")]).unwrap();
        let topic = markup.descendants().find(|n| n.has_tag_name("Topic")).unwrap();
        assert_eq!(topic.attribute("Guid"), Some(g.as_str()));
        assert_eq!(topic.attribute("TopicType"), Some("Clash"));
        let title = text(&markup, "Title")[0];
        assert!(title.contains("crossing world/sides#1:5:2:4:3 \u{d7} world/dowel#1:"), "{title}");
        // The description names the region, whose id is the stable finding id.
        let desc = text(&markup, "Description")[0];
        let region = rep.regions.iter().find(|r| desc.contains(&r.id)).expect("region id in description");
        assert!(title.contains(&region.b_name));
        assert_eq!(text(&markup, "Viewpoint"), ["viewpoint.bcfv"]);

        let vp = roxmltree::Document::parse(&files[&format!("{g}/viewpoint.bcfv")]).unwrap();
        // Both parts selected, by node path and file name (no IFC GUIDs in these names).
        assert_eq!(text(&vp, "AuthoringToolId")[..2], [region.a_name.as_str(), region.b_name.as_str()]);
        assert!(text(&vp, "OriginatingSystem").iter().all(|s| *s == "pins.glb"));
        let colors: Vec<&str> = vp.descendants().filter_map(|n| n.attribute("Color")).collect();
        assert_eq!(colors, ["FFFF800D", "FF1F78CC"]);
        // Camera: metres, Z up (glTF's (x, y, z) is (x, -z, y)); it looks at the region.
        let c = region.center;
        let centre = [c[0], -c[2], c[1]];
        let eye = xyz(&vp, "CameraViewPoint");
        let dir = xyz(&vp, "CameraDirection");
        let to_c: Vec<f64> = (0..3).map(|k| centre[k] - eye[k]).collect();
        let len = to_c.iter().map(|v| v * v).sum::<f64>().sqrt();
        let cos = (0..3).map(|k| to_c[k] / len * dir[k]).sum::<f64>();
        assert!(cos > 0.99, "camera does not look at the region: cos {cos}");
        assert!(len > 0.0 && len < rep.settings.model_size * 3.0, "{len}");
        let up = xyz(&vp, "CameraUpVector");
        assert!(up[2] > 0.5 && (0..3).map(|k| up[k] * dir[k]).sum::<f64>().abs() < 1e-9);
        assert_eq!(text(&vp, "FieldOfView"), ["60"]);
        // Contact segments as lines.
        assert!(vp.descendants().filter(|n| n.has_tag_name("Line")).count() >= 1);
    }
    // Deterministic: the same run gives the same archive.
    let (_, _, again) = run(d.path(), &["scene", &shipped("pins.glb"), "--threads", "1"]);
    assert_eq!(bytes, again);
}

#[test]
fn topic_guids_follow_finding_ids_across_runs_and_part_pairs_group() {
    let d = tempfile::tempdir().unwrap();
    let (all, _, _) = run(d.path(), &["scene", &shipped("pins.glb")]);
    // Without one dowel: the other five topics keep their GUIDs.
    let (fewer, _, _) = run(d.path(), &["scene", &shipped("pins.glb"), "--exclude", "*dowel#1:14*"]);
    let (ga, gf) = (topics(&all), topics(&fewer));
    assert_eq!(gf.len(), 5);
    assert!(gf.iter().all(|g| ga.contains(g)), "{gf:?} not in {ga:?}");

    let (pp, _, _) = run(d.path(), &["scene", &shipped("pins.glb"), "--bcf-topics", "part-pairs"]);
    let gp = topics(&pp);
    assert_eq!(gp.len(), 6); // one region per part pair here
    assert!(gp.iter().all(|g| !ga.contains(g)), "part-pair GUIDs differ from region GUIDs");
}

#[test]
fn two_files_in_model_units_and_witness_line() {
    let d = tempfile::tempdir().unwrap();
    let (files, rep, _) = run(d.path(), &[&shipped("fcl_env.obj"), &shipped("fcl_rob.obj"), "--units", "mm"]);
    let guids = topics(&files);
    assert_eq!(guids.len(), 1);
    let vp = roxmltree::Document::parse(&files[&format!("{}/viewpoint.bcfv", guids[0])]).unwrap();
    let systems = text(&vp, "OriginatingSystem");
    assert_eq!(systems[..2], ["fcl_env.obj", "fcl_rob.obj"]);
    // mm -> m, OBJ taken as Z up: the line ends are the contact segments / 1000.
    let lines: Vec<[f64; 3]> = vp
        .descendants()
        .filter(|n| n.has_tag_name("StartPoint"))
        .map(|n| {
            let c = |k: &str| {
                n.children().find(|c| c.has_tag_name(k)).unwrap().text().unwrap().parse::<f64>().unwrap()
            };
            [c("X"), c("Y"), c("Z")]
        })
        .collect();
    assert!(!lines.is_empty() && lines.len() <= 65);
    let g = &rep.regions[0];
    for p in &lines {
        for k in 0..3 {
            let (lo, hi) = (g.bounds.min[k] / 1000.0, g.bounds.max[k] / 1000.0);
            assert!(p[k] >= lo - 1e-6 && p[k] <= hi + 1e-6, "{p:?} outside the region box (m)");
        }
    }
}

#[test]
fn bcf_3_0_layout_same_topics_and_viewpoints() {
    let d = tempfile::tempdir().unwrap();
    let (v21, _, _) = run(d.path(), &["scene", &shipped("pins.glb")]);
    let (files, rep, _) = run(d.path(), &["scene", &shipped("pins.glb"), "--bcf-version", "3.0"]);
    // bcf.version: VersionId 3.0, no DetailedVersion (3.0 dropped it).
    let version = roxmltree::Document::parse(&files["bcf.version"]).unwrap();
    assert_eq!(version.root_element().tag_name().name(), "Version");
    assert_eq!(version.root_element().attribute("VersionId"), Some("3.0"));
    assert!(text(&version, "DetailedVersion").is_empty());
    // extensions.xml lists the values the topics use; every list of the schema is there.
    let ext = roxmltree::Document::parse(&files["extensions.xml"]).unwrap();
    let lists: Vec<&str> =
        ext.root_element().children().filter(|n| n.is_element()).map(|n| n.tag_name().name()).collect();
    assert_eq!(
        lists,
        ["TopicTypes", "TopicStatuses", "Priorities", "TopicLabels", "Users", "SnippetTypes", "Stages"]
    );
    assert_eq!(text(&ext, "TopicType"), ["Clash"]);
    assert_eq!(text(&ext, "TopicStatus"), ["Open"]);
    assert_eq!(text(&ext, "TopicLabel"), ["meshclash"]);
    // The same topics (GUIDs) as 2.1, one per region.
    let guids = topics(&files);
    assert_eq!(guids, topics(&v21));
    assert_eq!(guids.len(), rep.regions.len());
    assert_eq!(files.len(), 2 + 2 * guids.len());
    for g in &guids {
        let markup = roxmltree::Document::parse(&files[&format!("{g}/markup.bcf")]).unwrap();
        let top: Vec<&str> = markup
            .root_element()
            .children()
            .filter(|n| n.is_element())
            .map(|n| n.tag_name().name())
            .collect();
        assert_eq!(top, ["Topic"], "3.0: the viewpoints are inside the topic");
        let topic = markup.root_element().first_element_child().unwrap();
        assert_eq!(topic.attribute("Guid"), Some(g.as_str()));
        assert_eq!(topic.attribute("TopicType"), Some("Clash"));
        let order: Vec<&str> =
            topic.children().filter(|n| n.is_element()).map(|n| n.tag_name().name()).collect();
        assert_eq!(order, ["Title", "Labels", "CreationDate", "CreationAuthor", "Description", "Viewpoints"]);
        assert_eq!(text(&markup, "Label"), ["meshclash"]);
        let vp_ref = markup.descendants().find(|n| n.has_tag_name("ViewPoint")).unwrap();
        assert_eq!(text(&markup, "Viewpoint"), ["viewpoint.bcfv"]);
        let vp = roxmltree::Document::parse(&files[&format!("{g}/viewpoint.bcfv")]).unwrap();
        assert_eq!(vp.root_element().attribute("Guid"), vp_ref.attribute("Guid"));
        let cam = vp.descendants().find(|n| n.has_tag_name("PerspectiveCamera")).unwrap();
        let fields: Vec<&str> =
            cam.children().filter(|n| n.is_element()).map(|n| n.tag_name().name()).collect();
        assert_eq!(
            fields,
            ["CameraViewPoint", "CameraDirection", "CameraUpVector", "FieldOfView", "AspectRatio"]
        );
        // The viewpoint content is the 2.1 one plus the aspect ratio.
        let old = roxmltree::Document::parse(&v21[&format!("{g}/viewpoint.bcfv")]).unwrap();
        assert_eq!(xyz(&vp, "CameraViewPoint"), xyz(&old, "CameraViewPoint"));
        assert_eq!(text(&vp, "AuthoringToolId"), text(&old, "AuthoringToolId"));
    }
    // A bad version is a usage error.
    let out = Command::cargo_bin("meshclash")
        .unwrap()
        .args(["scene", &shipped("pins.glb"), "--bcf-version", "2.0", "--bcf", "x.bcfzip"])
        .current_dir(d.path())
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("2.1"));
}
