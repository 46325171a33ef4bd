#!/usr/bin/env bash
# meshclash on AWS Batch: an array job of N shards, then a merge job that depends
# on the whole array. Inputs, plan and shard reports live under one S3 prefix; each job copies
# what it needs. AWS Batch sets AWS_BATCH_JOB_ARRAY_INDEX (0-based) in every child and
# meshclash reads it itself (and AWS_BATCH_JOB_ARRAY_SIZE when set; --shards says N explicitly).
#
#   deploy/aws-batch/submit.sh s3://bucket/site-2024-06 QUEUE JOBDEF 8
#
# JOBDEF is a job definition whose image has meshclash and the aws CLI, and whose command is
# ["sh", "-c", "Ref::script"] (the scripts below are passed as the `script` parameter).
set -euo pipefail
prefix=$1 queue=$2 jobdef=$3 n=${4:-8}

# 1. Plan (here, or as a job of its own): the inputs go up with the plan; the paths in the
#    plan are relative, so every job works in a directory laid out the same way.
meshclash plan scene site.glb --clearance 10 --no-timings -o plan.json
aws s3 cp site.glb "$prefix/site.glb"
aws s3 cp plan.json "$prefix/plan.json"

shard_script='set -e; cd /tmp; aws s3 cp '"$prefix"'/site.glb site.glb; aws s3 cp '"$prefix"'/plan.json plan.json;
i=$((AWS_BATCH_JOB_ARRAY_INDEX + 1)); meshclash run --plan plan.json --shards '"$n"' -o shard-$i.json;
aws s3 cp shard-$i.json '"$prefix"'/shards/shard-$i.json'
array=$(aws batch submit-job --job-name meshclash-shards --job-queue "$queue" --job-definition "$jobdef" \
    --array-properties size="$n" --parameters script="$shard_script" --query jobId --output text)

merge_script='set -e; cd /tmp; aws s3 cp '"$prefix"'/site.glb site.glb; aws s3 cp --recursive '"$prefix"'/shards shards;
set +e; meshclash merge shards/shard-*.json --junit report.xml -o report.json; code=$?; set -e;
aws s3 cp report.json '"$prefix"'/report.json; aws s3 cp report.xml '"$prefix"'/report.xml; exit $code'
aws batch submit-job --job-name meshclash-merge --job-queue "$queue" --job-definition "$jobdef" \
    --depends-on jobId="$array" --parameters script="$merge_script" --query jobId --output text
