#!/usr/bin/env bash
# meshclash on Cloud Run jobs: one job execution with N tasks; every task reads
# CLOUD_RUN_TASK_INDEX (0-based) and CLOUD_RUN_TASK_COUNT, which meshclash reads itself. A
# Cloud Storage bucket mounted at /work (Cloud Storage FUSE volume) holds the inputs, the plan
# and the shard reports; the merge is a second job with one task.
#
#   deploy/cloud-run/job.sh BUCKET REGION IMAGE 8
set -euo pipefail
bucket=$1 region=$2 image=$3 n=${4:-8}

# Plan locally (or in a one-task job) and upload inputs + plan side by side.
meshclash plan scene site.glb --clearance 10 --no-timings -o plan.json
gcloud storage cp site.glb plan.json "gs://$bucket/"

gcloud run jobs deploy meshclash-shards --region "$region" --image "$image" \
    --tasks "$n" --parallelism "$n" --max-retries 1 --cpu 4 --memory 8Gi --task-timeout 24h \
    --add-volume name=work,type=cloud-storage,bucket="$bucket" \
    --add-volume-mount volume=work,mount-path=/work \
    --command sh --args=-c,'cd /work && mkdir -p shards && meshclash run --plan plan.json -o shards/shard-$((CLOUD_RUN_TASK_INDEX + 1)).json'
gcloud run jobs execute meshclash-shards --region "$region" --wait

gcloud run jobs deploy meshclash-merge --region "$region" --image "$image" --tasks 1 \
    --add-volume name=work,type=cloud-storage,bucket="$bucket" \
    --add-volume-mount volume=work,mount-path=/work \
    --command sh --args=-c,'cd /work && meshclash merge shards/shard-*.json --junit report.xml -o report.json'
# Exit 1 (findings at or above --fail-on) shows as a failed execution: read report.json.
gcloud run jobs execute meshclash-merge --region "$region" --wait || true
gcloud storage cp "gs://$bucket/report.json" "gs://$bucket/report.xml" .
